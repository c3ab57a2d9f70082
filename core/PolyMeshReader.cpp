#include "core/PolyMeshReader.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>

namespace mfsi {

namespace {

struct Token {
  enum class Kind { Punct, Word, String, End };
  Kind kind = Kind::End;
  std::string_view text;
  int line = 0;
};

/// Tokens of an OpenFOAM file: punctuation ( ) { } ;, words (numbers included) and "strings";
/// // and /* */ comments are skipped.
class FoamLexer {
 public:
  /// Open and read `dir/name`.
  FoamLexer(const std::string& dir, const std::string& name) : path_(dir + "/" + name) {
    std::ifstream in(path_, std::ios::binary);
    if (!in) {
      const bool gz = static_cast<bool>(std::ifstream(path_ + ".gz"));
      MFSI_CHECK(!gz, path_ << ".gz: compressed polyMesh files are not supported; gunzip them first");
      MFSI_CHECK(false, path_ << ": cannot open the polyMesh file (is " << dir << " a polyMesh directory?)");
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    text_ = ss.str();
  }
  // Tokens view into the text: no copies or moves.
  FoamLexer(const FoamLexer&) = delete;
  FoamLexer& operator=(const FoamLexer&) = delete;

  /// What the FoamFile header says.
  struct Header {
    std::string foamClass;
    long long nCells = -1;  ///< from `note "... nCells:N ..."` (OpenFOAM writes it in owner), -1: not given
  };
  /// Read the FoamFile header if there is one; rejects binary files.
  Header readHeader();

  Token next() {
    Token t = peek();
    pos_ = peekEnd_;
    line_ = peekLine_;
    havePeek_ = false;
    return t;
  }

  Token peek() {
    if (havePeek_) return peeked_;
    std::size_t p = pos_;
    int line = line_;
    skipSpaceAndComments(p, line);
    Token t;
    t.line = line;
    if (p >= text_.size()) {
      t.kind = Token::Kind::End;
    } else if (isPunct(text_[p])) {
      t.kind = Token::Kind::Punct;
      t.text = std::string_view(text_).substr(p, 1);
      ++p;
    } else if (text_[p] == '"') {
      const std::size_t close = text_.find('"', p + 1);
      if (close == std::string::npos) failAt(line, "unterminated string");
      t.kind = Token::Kind::String;
      t.text = std::string_view(text_).substr(p + 1, close - p - 1);
      line += static_cast<int>(std::count(text_.begin() + p, text_.begin() + close, '\n'));
      p = close + 1;
    } else {
      const std::size_t start = p;
      while (p < text_.size() && !isSpace(text_[p]) && !isPunct(text_[p]) && text_[p] != '"' && !commentAt(p)) ++p;
      t.kind = Token::Kind::Word;
      t.text = std::string_view(text_).substr(start, p - start);
    }
    peeked_ = t;
    peekEnd_ = p;
    peekLine_ = line;
    havePeek_ = true;
    return t;
  }

  /// Name the list item being read ("point", 12), for messages; nullptr: none. No string is
  /// built per token.
  void setItem(const char* kind, long long index) {
    itemKind_ = kind;
    itemIndex_ = index;
  }

  /// Consume the punctuation character `c` or fail; `what` says where we are.
  Token expectPunct(char c, const char* what) {
    const Token t = next();
    if (t.kind != Token::Kind::Punct || t.text[0] != c)
      failAt(t.line, std::string("expected '") + c + "' " + what + ", found " + describe(t));
    return t;
  }

  long long integer(const char* what) {
    const Token t = next();
    long long v = 0;
    if (t.kind == Token::Kind::Word) {
      const auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
      if (ec == std::errc() && end == t.text.data() + t.text.size()) return v;
    }
    failAt(t.line, std::string("expected ") + what + " (an integer), found " + describe(t));
  }

  /// A label: a non-negative integer that fits lid_t.
  lid_t label(const char* what) {
    const long long v = integer(what);
    if (v < 0 || v > 2147483647LL) failAt(lastLine(), std::string(what) + " " + std::to_string(v) + " is out of range");
    return static_cast<lid_t>(v);
  }

  double real(const char* what) {
    const Token t = next();
    if (t.kind == Token::Kind::Word) {
      std::string_view s = t.text;
      if (!s.empty() && s[0] == '+') s.remove_prefix(1);  // from_chars rejects a leading '+'
      double v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec == std::errc() && end == s.data() + s.size()) return v;
    }
    failAt(t.line, std::string("expected ") + what + " (a number), found " + describe(t));
  }

  int lastLine() const { return line_; }
  const std::string& path() const { return path_; }
  /// Bytes of the file not read yet.
  std::size_t bytesLeft() const { return text_.size() - std::min(pos_, text_.size()); }

  [[noreturn]] void failAt(int line, const std::string& msg) const {
    const std::string item = itemKind_ ? std::string(itemKind_) + " " + std::to_string(itemIndex_) + ": " : "";
    throw InputError(SourceLocation{path_, line, 0, ""}, item + msg);
  }

  static std::string describe(const Token& t) {
    if (t.kind == Token::Kind::End) return "the end of the file (truncated file?)";
    return "'" + std::string(t.text) + "'";
  }

 private:
  static bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
  static bool isPunct(char c) { return c == '(' || c == ')' || c == '{' || c == '}' || c == ';'; }
  bool commentAt(std::size_t p) const {
    return text_[p] == '/' && p + 1 < text_.size() && (text_[p + 1] == '/' || text_[p + 1] == '*');
  }

  void skipSpaceAndComments(std::size_t& p, int& line) const {
    while (p < text_.size()) {
      if (isSpace(text_[p])) {
        if (text_[p] == '\n') ++line;
        ++p;
      } else if (commentAt(p) && text_[p + 1] == '/') {
        while (p < text_.size() && text_[p] != '\n') ++p;
      } else if (commentAt(p)) {
        const std::size_t close = text_.find("*/", p + 2);
        if (close == std::string::npos) failAt(line, "unterminated /* comment");
        line += static_cast<int>(std::count(text_.begin() + p, text_.begin() + close, '\n'));
        p = close + 2;
      } else {
        return;
      }
    }
  }

  std::string path_;
  std::string text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  const char* itemKind_ = nullptr;
  long long itemIndex_ = -1;
  bool havePeek_ = false;
  Token peeked_;
  std::size_t peekEnd_ = 0;
  int peekLine_ = 1;
};

FoamLexer::Header FoamLexer::readHeader() {
  FoamLexer& lx = *this;
  Header h;
  const Token first = lx.peek();
  if (first.kind == Token::Kind::Word && first.text == "FoamFile") {
    lx.next();
    lx.expectPunct('{', "after FoamFile");
    for (;;) {
      const Token key = lx.next();
      if (key.kind == Token::Kind::Punct && key.text[0] == '}') break;
      if (key.kind != Token::Kind::Word) lx.failAt(key.line, "bad FoamFile header entry " + FoamLexer::describe(key));
      const Token value = lx.next();
      if (value.kind == Token::Kind::End) lx.failAt(value.line, "unterminated FoamFile header");
      if (key.text == "format" && value.text != "ascii")
        lx.failAt(value.line, "format '" + std::string(value.text) +
                                  "' is not supported, only ascii (set writeFormat ascii in system/controlDict "
                                  "and run foamFormatConvert)");
      if (key.text == "class") h.foamClass = std::string(value.text);
      if (key.text == "note") {
        const std::string_view note = value.text;
        const std::size_t at = note.find("nCells:");
        if (at != std::string_view::npos) {
          std::size_t p = at + 7;
          while (p < note.size() && note[p] == ' ') ++p;
          long long n = -1;
          const auto [end, ec] = std::from_chars(note.data() + p, note.data() + note.size(), n);
          if (ec == std::errc() && end != note.data() + p) h.nCells = n;
        }
      }
      for (Token t = value; !(t.kind == Token::Kind::Punct && t.text[0] == ';'); t = lx.next())
        if (t.kind == Token::Kind::End) lx.failAt(t.line, "unterminated FoamFile header");
    }
  }
  return h;
}

/// Start of a list: "N (" or "(". Returns N, or -1 when the size is not given. An entry takes at
/// least `minBytes` characters with its separator, so an N the rest of the file cannot hold, or one
/// lid_t cannot index, is refused here, before anything is reserved for it.
long long listStart(FoamLexer& lx, const std::string& what, std::size_t minBytes) {
  long long n = -1;
  if (lx.peek().kind == Token::Kind::Word) {
    n = lx.integer(("the size of the " + what + " list").c_str());
    const long long fits = static_cast<long long>(lx.bytesLeft() / minBytes) + 1;
    std::string why;
    if (n < 0)
      why = "a size cannot be negative";
    else if (n > fits)
      why = "the rest of the file (" + std::to_string(lx.bytesLeft()) + " bytes) holds at most " + std::to_string(fits);
    else if (n > std::numeric_limits<lid_t>::max())
      why = "one rank indexes at most " + std::to_string(std::numeric_limits<lid_t>::max()) + " (lid_t is 32-bit)";
    if (!why.empty())
      lx.failAt(lx.lastLine(), "the " + what + " list announces " + std::to_string(n) + " entries, but " + why);
  }
  const Token open = lx.peek();
  if (open.kind == Token::Kind::Punct && open.text[0] == '{')
    lx.failAt(open.line, "uniform list syntax N{...} is not supported for the " + what + " list");
  lx.expectPunct('(', ("opening the " + what + " list").c_str());
  return n;
}

bool atListEnd(FoamLexer& lx) {
  const Token t = lx.peek();
  if (t.kind == Token::Kind::Punct && t.text[0] == ')') {
    lx.next();
    return true;
  }
  return false;
}

void listEnd(FoamLexer& lx, long long expected, std::size_t got, const std::string& what) {
  if (expected >= 0 && static_cast<long long>(got) != expected)
    lx.failAt(lx.lastLine(), "the " + what + " list announces " + std::to_string(expected) + " entries but holds " +
                                 std::to_string(got));
  const Token t = lx.next();
  if (t.kind != Token::Kind::End)
    lx.failAt(t.line, "unexpected " + FoamLexer::describe(t) + " after the " + what + " list");
}

std::vector<std::array<real, 3>> readPoints(const std::string& dir) {
  FoamLexer lx(dir, "points");
  lx.readHeader();
  const long long n = listStart(lx, "points", 7);  // "(x y z)"
  std::vector<std::array<real, 3>> pts;
  if (n > 0) pts.reserve(static_cast<std::size_t>(n));
  while (!atListEnd(lx)) {
    lx.setItem("point", static_cast<long long>(pts.size()));
    lx.expectPunct('(', "opening the point");
    std::array<real, 3> p;
    for (auto& x : p) x = lx.real("a coordinate");
    lx.expectPunct(')', "closing the point");
    pts.push_back(p);
  }
  lx.setItem(nullptr, -1);
  listEnd(lx, n, pts.size(), "points");
  return pts;
}

struct FaceList {
  std::vector<std::array<lid_t, 4>> quads;
  std::vector<int> size;  ///< vertex count of each face as read
  std::vector<int> line;  ///< where each face starts in the file
};

FaceList readFaces(const std::string& dir) {
  FoamLexer lx(dir, "faces");
  const std::string cls = lx.readHeader().foamClass;
  MFSI_CHECK(cls != "faceCompactList", lx.path() << ": compact face lists (faceCompactList) are not supported; "
                                                    "write the mesh in ascii format as a faceList");
  const long long n = listStart(lx, "faces", 3);  // "0()"
  FaceList fl;
  while (!atListEnd(lx)) {
    lx.setItem("face", static_cast<long long>(fl.quads.size()));
    const long long nv = lx.integer("the vertex count");
    fl.line.push_back(lx.lastLine());
    lx.expectPunct('(', "opening the vertex list");
    std::array<lid_t, 4> q{-1, -1, -1, -1};
    int k = 0;
    while (!atListEnd(lx)) {
      const lid_t v = lx.label("a vertex");
      if (k < 4) q[k] = v;
      ++k;
    }
    if (k != nv)
      lx.failAt(fl.line.back(), "announces " + std::to_string(nv) + " vertices but lists " + std::to_string(k));
    fl.quads.push_back(q);
    fl.size.push_back(k);
  }
  lx.setItem(nullptr, -1);
  listEnd(lx, n, fl.quads.size(), "faces");
  return fl;
}

/// The cell labels of `owner` or `neighbour`. Cells are numbered by these labels, so each must lie
/// in [0, nCells): nCells is the header's note where it gives one, and at most half the number of
/// faces in any case (a cell has at least four faces, a face at most two cells). A label past that
/// is refused here, naming its line, instead of sizing the cell arrays.
std::vector<lid_t> readLabels(const std::string& dir, const std::string& name, lid_t nFaces) {
  FoamLexer lx(dir, name);
  const FoamLexer::Header header = lx.readHeader();
  const long long faceBound = nFaces / 2;
  const bool fromNote = header.nCells >= 0 && header.nCells <= faceBound;
  const long long nCells = fromNote ? header.nCells : faceBound;
  const std::string why =
      fromNote ? "the header's note gives nCells " + std::to_string(nCells)
               : "the mesh has " + std::to_string(nFaces) + " faces, so at most " + std::to_string(nCells) + " cells";
  const long long n = listStart(lx, name, 2);  // "0 "
  std::vector<lid_t> v;
  if (n > 0) v.reserve(static_cast<std::size_t>(n));
  while (!atListEnd(lx)) {
    lx.setItem("entry", static_cast<long long>(v.size()));
    // Old meshes pad neighbour with -1 for boundary faces.
    const long long x = lx.integer("a cell label");
    if (x < -1 || x >= nCells)
      lx.failAt(lx.lastLine(),
                "cell label " + std::to_string(x) + " is out of range [0, " + std::to_string(nCells) + "): " + why);
    v.push_back(static_cast<lid_t>(x));
  }
  lx.setItem(nullptr, -1);
  listEnd(lx, n, v.size(), name);
  return v;
}

struct BoundaryEntry {
  std::string name, type;
  long long nFaces = -1, startFace = -1;
  int line = 0;
};

std::vector<BoundaryEntry> readBoundary(const std::string& dir) {
  FoamLexer lx(dir, "boundary");
  lx.readHeader();
  const long long n = listStart(lx, "boundary", 3);  // "p{}"
  std::vector<BoundaryEntry> out;
  while (!atListEnd(lx)) {
    BoundaryEntry e;
    const Token name = lx.next();
    if (name.kind != Token::Kind::Word && name.kind != Token::Kind::String)
      lx.failAt(name.line, "expected a patch name, found " + FoamLexer::describe(name));
    e.name = std::string(name.text);
    e.line = name.line;
    lx.expectPunct('{', ("opening patch '" + e.name + "'").c_str());
    for (;;) {
      const Token key = lx.next();
      if (key.kind == Token::Kind::Punct && key.text[0] == '}') break;
      if (key.kind != Token::Kind::Word)
        lx.failAt(key.line, "expected an entry of patch '" + e.name + "', found " + FoamLexer::describe(key));
      // The value runs to ';' outside parentheses (e.g. "inGroups List<word> 1(wall);"), or is a sub-dictionary.
      std::vector<Token> value;
      int depth = 0;
      for (;;) {
        const Token t = lx.next();
        if (t.kind == Token::Kind::End)
          lx.failAt(t.line, "unterminated entry '" + std::string(key.text) + "' of patch '" + e.name + "'");
        if (t.kind == Token::Kind::Punct) {
          const char c = t.text[0];
          if (c == '(' || c == '{') ++depth;
          if (c == ')' || c == '}') --depth;
          if (depth < 0)
            lx.failAt(t.line, "missing ';' after entry '" + std::string(key.text) + "' of patch '" + e.name + "'");
          if ((c == ';' && depth == 0) ||
              (c == '}' && depth == 0 && !value.empty() && value[0].kind == Token::Kind::Punct && value[0].text == "{"))
            break;
        }
        value.push_back(t);
      }
      if (value.empty()) continue;
      auto asLabel = [&](const Token& t) {
        long long v = -1;
        const auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
        if (ec != std::errc() || end != t.text.data() + t.text.size() || v < 0)
          lx.failAt(t.line,
                    "bad " + std::string(key.text) + " '" + std::string(t.text) + "' in patch '" + e.name + "'");
        return v;
      };
      if (key.text == "type") e.type = std::string(value[0].text);
      if (key.text == "nFaces") e.nFaces = asLabel(value[0]);
      if (key.text == "startFace") e.startFace = asLabel(value[0]);
    }
    if (e.type.empty() || e.nFaces < 0 || e.startFace < 0)
      lx.failAt(e.line, "patch '" + e.name + "' needs type, nFaces and startFace");
    out.push_back(e);
  }
  listEnd(lx, n, out.size(), "boundary");
  return out;
}

PatchKind kindOf(const std::string& type) {
  if (type == "wall") return PatchKind::Wall;
  if (type == "symmetry" || type == "symmetryPlane") return PatchKind::Symmetry;
  if (type == "empty") return PatchKind::Empty;
  return PatchKind::Patch;
}

}  // namespace

HexMeshInput readPolyMesh(const std::string& dir) {
  ScopedRegion region("mfsi::core::io::readPolyMesh");
  HexMeshInput out;
  out.source = dir;
  out.points = readPoints(dir);
  const FaceList faces = readFaces(dir);
  const std::vector<lid_t> owner = readLabels(dir, "owner", static_cast<lid_t>(faces.quads.size()));
  const std::vector<lid_t> neighbour = readLabels(dir, "neighbour", static_cast<lid_t>(faces.quads.size()));
  const std::vector<BoundaryEntry> boundary = readBoundary(dir);

  const std::string facesPath = dir + "/faces", ownerPath = dir + "/owner", neighbourPath = dir + "/neighbour";
  const auto nPoints = static_cast<lid_t>(out.points.size());
  const auto nFaces = static_cast<lid_t>(faces.quads.size());
  MFSI_CHECK(static_cast<lid_t>(owner.size()) == nFaces,
             ownerPath << ": " << owner.size() << " entries, but " << facesPath << " has " << nFaces << " faces");
  MFSI_CHECK(static_cast<lid_t>(neighbour.size()) <= nFaces, neighbourPath << ": " << neighbour.size()
                                                                           << " entries, but " << facesPath
                                                                           << " has only " << nFaces << " faces");
  auto neighbourOf = [&](lid_t f) { return f < static_cast<lid_t>(neighbour.size()) ? neighbour[f] : -1; };

  lid_t nCells = 0;
  for (lid_t f = 0; f < nFaces; ++f) {
    MFSI_CHECK(owner[f] >= 0, ownerPath << ": face " << f << " has no owner cell");
    nCells = std::max({nCells, owner[f] + 1, neighbourOf(f) + 1});
  }
  MFSI_CHECK(nCells > 0, dir << ": the mesh has no cells");

  // Cell -> faces (CSR), and the face checks that name the faces file and line.
  std::vector<lid_t> offset(nCells + 1, 0);
  for (lid_t f = 0; f < nFaces; ++f) {
    ++offset[owner[f] + 1];
    if (neighbourOf(f) >= 0) ++offset[neighbourOf(f) + 1];
  }
  for (lid_t c = 0; c < nCells; ++c) offset[c + 1] += offset[c];
  std::vector<lid_t> cellFace(offset[nCells]);
  {
    std::vector<lid_t> fill(offset.begin(), offset.end() - 1);
    for (lid_t f = 0; f < nFaces; ++f) {
      cellFace[fill[owner[f]]++] = f;
      if (neighbourOf(f) >= 0) cellFace[fill[neighbourOf(f)]++] = f;
    }
  }
  for (lid_t f = 0; f < nFaces; ++f) {
    if (faces.size[f] != 4)
      throw InputError(SourceLocation{facesPath, faces.line[f], 0, ""},
                       "non-hex cell " + std::to_string(owner[f]) + ": face " + std::to_string(f) + " has " +
                           std::to_string(faces.size[f]) +
                           " vertices; only hexahedral cells (six 4-vertex faces) are supported");
    for (const lid_t v : faces.quads[f])
      if (v >= nPoints)
        throw InputError(SourceLocation{facesPath, faces.line[f], 0, ""},
                         "face " + std::to_string(f) + " refers to point " + std::to_string(v) + " but " + dir +
                             "/points has " + std::to_string(nPoints) + " points");
  }

  // Rebuild each cell's 8 nodes from its 6 quads.
  out.cells.resize(nCells);
  for (lid_t c = 0; c < nCells; ++c) {
    const lid_t nf = offset[c + 1] - offset[c];
    MFSI_CHECK(nf == 6, ownerPath << ": non-hex cell " << c << " has " << nf
                                  << " faces (owner/neighbour); only hexahedra (six 4-vertex faces) are supported");
    // Faces point out of their owner; turn the neighbour's ones around so all six point out of c.
    std::array<std::array<lid_t, 4>, 6> q;
    for (int i = 0; i < 6; ++i) {
      const lid_t f = cellFace[offset[c] + i];
      q[i] = faces.quads[f];
      if (owner[f] != c) std::reverse(q[i].begin(), q[i].end());
    }
    // Our bottom face (0 1 2 3) has its right-hand normal pointing into the cell, so it is the
    // first face read backwards.
    std::array<lid_t, 8> n{q[0][0], q[0][3], q[0][2], q[0][1], -1, -1, -1, -1};
    auto inBottom = [&](lid_t v) { return v == n[0] || v == n[1] || v == n[2] || v == n[3]; };
    bool ok = true;
    // Each bottom node has exactly one edge leaving the bottom face: its other end is the node above.
    for (int i = 0; i < 4 && ok; ++i)
      for (const auto& face : q)
        for (int k = 0; k < 4; ++k) {
          const lid_t a = face[k], b = face[(k + 1) % 4];
          const lid_t other = a == n[i] ? b : (b == n[i] ? a : -1);
          if (other < 0 || inBottom(other)) continue;
          if (n[4 + i] >= 0 && n[4 + i] != other) ok = false;
          n[4 + i] = other;
        }
    for (int a = 0; a < 8 && ok; ++a) {
      if (n[a] < 0) ok = false;
      for (int b = 0; b < a && ok; ++b) ok = n[a] != n[b];
    }
    if (ok) {
      // The six faces of the rebuilt hex must be exactly the cell's faces.
      std::array<std::array<lid_t, 4>, 6> want, have;
      for (int i = 0; i < 6; ++i) {
        for (int k = 0; k < 4; ++k) want[i][k] = n[kHexFaces[i][k]];
        have[i] = q[i];
        std::sort(want[i].begin(), want[i].end());
        std::sort(have[i].begin(), have[i].end());
      }
      std::sort(want.begin(), want.end());
      std::sort(have.begin(), have.end());
      ok = want == have;
    }
    MFSI_CHECK(ok, facesPath << ": non-hex cell " << c << ": its six 4-vertex faces do not close up as a hexahedron");
    // With faces pointing out of their owner the hex is right-handed. A mesh that breaks the
    // convention (e.g. mirrored without flipping its faces) is still unambiguous: mirror the node
    // order so the volume is positive instead of failing.
    double x[8][3], vol = 0, centroid[3];
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k) x[a][k] = out.points[n[a]][k];
    geom::hexVolumeCentroid(x, vol, centroid);
    if (vol < 0) {
      std::swap(n[1], n[3]);
      std::swap(n[5], n[7]);
    }
    out.cells[c] = n;
  }

  const std::string boundaryPath = dir + "/boundary";
  for (const auto& e : boundary) {
    const SourceLocation where{boundaryPath, e.line, 0, ""};
    if (e.type == "processor" || e.type == "processorCyclic")
      throw InputError(where, "patch '" + e.name + "' of type " + e.type +
                                  ": this is one piece of a decomposed mesh; read the undecomposed mesh "
                                  "(or run reconstructParMesh) instead");
    if (e.nFaces > nFaces || e.startFace > nFaces - e.nFaces)
      throw InputError(where, "patch '" + e.name + "' (startFace " + std::to_string(e.startFace) + ", nFaces " +
                                  std::to_string(e.nFaces) + ") runs past the " + std::to_string(nFaces) +
                                  " faces of the mesh");
    HexMeshInput::PatchSpec p;
    p.name = e.name;
    p.kind = kindOf(e.type);
    for (auto f = static_cast<lid_t>(e.startFace); f < e.startFace + e.nFaces; ++f) {
      if (neighbourOf(f) >= 0)
        throw InputError(where, "patch '" + e.name + "' contains face " + std::to_string(f) +
                                    ", which is an internal face (it has a neighbour cell)");
      p.faces.push_back(faces.quads[f]);
    }
    out.patches.push_back(std::move(p));
  }
  return out;
}

}  // namespace mfsi
