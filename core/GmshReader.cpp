#include "core/GmshReader.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace mfsi {

namespace {

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  MFSI_CHECK(in, path << ": cannot open the Gmsh mesh file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Gmsh element type names, for messages.
std::string elementTypeName(long long type) {
  switch (type) {
    case 1:
      return "2-node line";
    case 2:
      return "3-node triangle";
    case 3:
      return "4-node quadrangle";
    case 4:
      return "4-node tetrahedron";
    case 5:
      return "8-node hexahedron";
    case 6:
      return "6-node prism";
    case 7:
      return "5-node pyramid";
    case 9:
      return "6-node triangle";
    case 10:
      return "9-node quadrangle";
    case 11:
      return "10-node tetrahedron";
    case 12:
      return "27-node hexahedron";
    case 13:
      return "18-node prism";
    case 14:
      return "14-node pyramid";
    case 15:
      return "1-node point";
    case 16:
      return "8-node quadrangle";
    case 17:
      return "20-node hexahedron";
    case 18:
      return "15-node prism";
    case 19:
      return "13-node pyramid";
    default:
      return "element of type " + std::to_string(type);
  }
}

/// Whitespace-separated tokens of an MSH file, with the line each one sits on.
class Lexer {
 public:
  Lexer(std::string path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  /// True when only whitespace is left.
  bool atEnd() {
    skipSpace();
    return pos_ >= text_.size();
  }

  /// Name the element being read, for messages (-1: none). Cheap: no string is built per token.
  void setElement(long long tag) { element_ = tag; }

  /// The next token; `what` names what was expected, for the end-of-file message.
  std::string_view next(const char* what) {
    skipSpace();
    if (pos_ >= text_.size()) {
      tokenLine_ = line_;
      fail("unexpected end of file while reading " + describe(what) + " (truncated file?)");
    }
    tokenLine_ = line_;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
  }

  long long integer(const char* what) {
    const std::string_view tok = next(what);
    long long v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size())
      fail("expected " + describe(what) + " (an integer), found '" + std::string(tok) + "'");
    return v;
  }

  /// An integer that must fit a non-negative `int` (counts, types, dimensions).
  int count(const char* what) {
    const long long v = integer(what);
    if (v < 0 || v > 2147483647LL) fail(describe(what) + " " + std::to_string(v) + " is out of range");
    return static_cast<int>(v);
  }

  double real(const char* what) {
    std::string_view tok = next(what);
    const std::string_view full = tok;
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);  // from_chars rejects a leading '+'
    double v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size())
      fail("expected " + describe(what) + " (a number), found '" + std::string(full) + "'");
    return v;
  }

  /// A "quoted string" (may contain spaces), or a bare token.
  std::string quoted(const char* what) {
    skipSpace();
    if (pos_ < text_.size() && text_[pos_] == '"') {
      tokenLine_ = line_;
      const std::size_t close = text_.find_first_of("\"\n", pos_ + 1);
      if (close == std::string::npos || text_[close] != '"') fail(std::string("unterminated quoted ") + what);
      std::string s = text_.substr(pos_ + 1, close - pos_ - 1);
      pos_ = close + 1;
      return s;
    }
    return std::string(next(what));
  }

  /// The rest of the current line must be blank: catches elements with too many nodes.
  void expectLineEnd(const char* what) {
    while (pos_ < text_.size() && text_[pos_] != '\n' && isSpace(text_[pos_])) ++pos_;
    if (pos_ < text_.size() && text_[pos_] != '\n') {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
      fail("unexpected '" + text_.substr(start, pos_ - start) + "' after " + describe(what));
    }
  }

  /// Drop the rest of the current line (elements this reader ignores; Gmsh writes one per line).
  void skipLine() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }

  /// Skip tokens up to and including `endToken`.
  void skipTo(const std::string& endToken) {
    while (next(endToken.c_str()) != endToken) {
    }
  }

  void expect(const std::string& token) {
    const std::string_view tok = next(token.c_str());
    if (tok != token) fail("expected '" + token + "', found '" + std::string(tok) + "'");
  }

  int line() const { return tokenLine_; }
  const std::string& path() const { return path_; }

  [[noreturn]] void fail(const std::string& msg) const { failAt(tokenLine_, msg); }
  [[noreturn]] void failAt(int line, const std::string& msg) const {
    throw InputError(SourceLocation{path_, line, 0, ""}, msg);
  }

 private:
  static bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
  std::string describe(const char* what) const {
    return element_ >= 0 ? std::string(what) + " of element " + std::to_string(element_) : std::string(what);
  }
  void skipSpace() {
    while (pos_ < text_.size() && isSpace(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }

  std::string path_;
  std::string text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int tokenLine_ = 1;
  long long element_ = -1;
};

struct RawHex {
  std::array<lid_t, 8> nodes;  // indices into the file's node list
  long long tag;
  int line;
};

struct RawQuad {
  std::array<lid_t, 4> nodes;
  int physical;
  long long tag;
  int line;
};

/// Everything the sections deliver, before renumbering.
struct GmshData {
  std::map<int, std::string> surfaceNames;                     // physical tag (dim 2) -> name
  std::unordered_map<int, std::vector<int>> surfacePhysicals;  // surface entity -> physical tags
  std::vector<std::array<real, 3>> coords;
  std::vector<long long> nodeTag;
  std::unordered_map<long long, lid_t> nodeIndex;  // tag -> index into coords
  std::vector<RawHex> hexes;
  std::vector<RawQuad> quads;
};

void readFormat(Lexer& lx) {
  const std::string version(lx.next("the format version"));
  const int versionLine = lx.line();
  if (version != "4.1")
    lx.failAt(versionLine, "MSH format version " + version +
                               " is not supported; only MSH 4.1 ASCII is read (export with Gmsh's "
                               "'-format msh41' option or Mesh.MshFileVersion = 4.1)");
  const int fileType = lx.count("the file type (0 = ASCII, 1 = binary)");
  if (fileType != 0)
    lx.fail("binary MSH files are not supported; only MSH 4.1 ASCII is read (save with Mesh.Binary = 0)");
  lx.count("the data size");
  lx.expect("$EndMeshFormat");
}

void readPhysicalNames(Lexer& lx, GmshData& d) {
  const int n = lx.count("the number of physical names");
  for (int i = 0; i < n; ++i) {
    const int dim = lx.count("a physical group dimension");
    const int tag = static_cast<int>(lx.integer("a physical group tag"));
    std::string name = lx.quoted("physical group name");
    if (dim == 2) d.surfaceNames[tag] = std::move(name);
  }
  lx.expect("$EndPhysicalNames");
}

void readEntities(Lexer& lx, GmshData& d) {
  int n[4];
  n[0] = lx.count("the number of point entities");
  n[1] = lx.count("the number of curve entities");
  n[2] = lx.count("the number of surface entities");
  n[3] = lx.count("the number of volume entities");
  for (int dim = 0; dim < 4; ++dim)
    for (int e = 0; e < n[dim]; ++e) {
      const int tag = static_cast<int>(lx.integer("an entity tag"));
      // A point carries its position, the other entities a bounding box.
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) lx.real("an entity coordinate");
      const int nPhys = lx.count("the number of physical tags");
      std::vector<int> phys(nPhys);
      for (auto& p : phys) p = static_cast<int>(lx.integer("a physical tag"));
      if (dim > 0) {
        const int nBound = lx.count("the number of bounding entities");
        for (int b = 0; b < nBound; ++b) lx.integer("a bounding entity tag");
      }
      // Gmsh writes signed physical tags in rare cases (orientation); the group is |tag|.
      for (auto& p : phys) p = std::abs(p);
      if (dim == 2) d.surfacePhysicals[tag] = std::move(phys);
    }
  lx.expect("$EndEntities");
}

void readNodes(Lexer& lx, GmshData& d) {
  const long long nBlocks = lx.integer("the number of node blocks");
  const long long nNodes = lx.integer("the number of nodes");
  if (nBlocks < 0 || nNodes < 0 || nNodes > 2147483647LL) lx.fail("bad $Nodes header");
  lx.integer("the minimum node tag");
  lx.integer("the maximum node tag");
  d.coords.reserve(static_cast<std::size_t>(nNodes));
  d.nodeTag.reserve(static_cast<std::size_t>(nNodes));
  d.nodeIndex.reserve(static_cast<std::size_t>(nNodes));
  for (long long b = 0; b < nBlocks; ++b) {
    const int dim = lx.count("the entity dimension of a node block");
    lx.integer("the entity tag of a node block");
    const int parametric = lx.count("the parametric flag of a node block");
    const int n = lx.count("the number of nodes in a block");
    if (dim > 3) lx.fail("node block of dimension " + std::to_string(dim));
    const std::size_t first = d.coords.size();
    for (int i = 0; i < n; ++i) {
      const long long tag = lx.integer("a node tag");
      const auto index = static_cast<lid_t>(d.nodeTag.size());
      if (!d.nodeIndex.emplace(tag, index).second) lx.fail("node tag " + std::to_string(tag) + " appears twice");
      d.nodeTag.push_back(tag);
    }
    d.coords.resize(first + n);
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) d.coords[first + i][k] = lx.real("a node coordinate");
      // Parametric coordinates (u, v, w up to the entity dimension) follow; we do not need them.
      if (parametric) {
        for (int k = 0; k < dim; ++k) lx.real("a parametric node coordinate");
      }
    }
  }
  if (static_cast<long long>(d.coords.size()) != nNodes)
    lx.fail("the $Nodes header announces " + std::to_string(nNodes) + " nodes but its blocks hold " +
            std::to_string(d.coords.size()));
  lx.expect("$EndNodes");
}

lid_t nodeOf(Lexer& lx, const GmshData& d, long long elementTag) {
  const long long tag = lx.integer("a node tag");
  const auto it = d.nodeIndex.find(tag);
  if (it == d.nodeIndex.end())
    lx.fail("element " + std::to_string(elementTag) + " refers to unknown node tag " + std::to_string(tag));
  return it->second;
}

void readElements(Lexer& lx, GmshData& d) {
  const long long nBlocks = lx.integer("the number of element blocks");
  const long long nElements = lx.integer("the number of elements");
  if (nBlocks < 0 || nElements < 0) lx.fail("bad $Elements header");
  lx.integer("the minimum element tag");
  lx.integer("the maximum element tag");
  long long seen = 0;
  for (long long b = 0; b < nBlocks; ++b) {
    const int dim = lx.count("the entity dimension of an element block");
    const int entity = static_cast<int>(lx.integer("the entity tag of an element block"));
    const int type = lx.count("the element type of an element block");
    const int n = lx.count("the number of elements in a block");
    const int blockLine = lx.line();
    seen += n;
    if (dim > 3) lx.fail("element block of dimension " + std::to_string(dim));
    if (type == 5 && dim != 3) lx.fail("hexahedra (type 5) in an element block of dimension " + std::to_string(dim));
    if (dim == 3 && type != 5) {
      if (n == 0) continue;
      const long long tag = lx.integer("an element tag");
      lx.fail("non-hex cell: element " + std::to_string(tag) + " is a " + elementTypeName(type) +
              " (Gmsh element type " + std::to_string(type) + "); only 8-node hexahedra (type 5) are supported");
    }
    if (dim == 3) {
      for (int i = 0; i < n; ++i) {
        RawHex h;
        h.tag = lx.integer("an element tag");
        h.line = lx.line();
        lx.setElement(h.tag);
        for (auto& v : h.nodes) v = nodeOf(lx, d, h.tag);
        lx.expectLineEnd("the 8 node tags");
        lx.setElement(-1);
        d.hexes.push_back(h);
      }
      continue;
    }
    const auto phys = dim == 2 ? d.surfacePhysicals.find(entity) : d.surfacePhysicals.end();
    if (phys == d.surfacePhysicals.end() || phys->second.empty()) {
      // Not a boundary patch: 0D/1D elements and surfaces outside any physical group.
      for (int i = 0; i < n; ++i) {
        lx.integer("an element tag");
        lx.skipLine();
      }
      continue;
    }
    if (phys->second.size() > 1)
      lx.failAt(blockLine, "surface entity " + std::to_string(entity) + " belongs to " +
                               std::to_string(phys->second.size()) +
                               " physical groups; a boundary face can only be in one patch");
    if (type != 3) {
      if (n == 0) continue;
      const long long tag = lx.integer("an element tag");
      lx.fail("boundary element " + std::to_string(tag) + " on physical surface " + std::to_string(phys->second[0]) +
              " is a " + elementTypeName(type) + "; the boundary of a hex mesh is made of 4-node quadrangles (type 3)");
    }
    for (int i = 0; i < n; ++i) {
      RawQuad q;
      q.tag = lx.integer("an element tag");
      q.line = lx.line();
      q.physical = phys->second[0];
      lx.setElement(q.tag);
      for (auto& v : q.nodes) v = nodeOf(lx, d, q.tag);
      lx.expectLineEnd("the 4 node tags");
      lx.setElement(-1);
      d.quads.push_back(q);
    }
  }
  if (seen != nElements)
    lx.fail("the $Elements header announces " + std::to_string(nElements) + " elements but its blocks hold " +
            std::to_string(seen));
  lx.expect("$EndElements");
}

}  // namespace

HexMeshInput readGmsh(const std::string& path) {
  ScopedRegion region("mfsi::core::io::readGmsh");
  Lexer lx(path, readWholeFile(path));
  GmshData d;
  bool haveFormat = false, haveNodes = false, haveElements = false;
  while (!lx.atEnd()) {
    const std::string_view tok = lx.next("a section");
    if (tok.size() < 2 || tok[0] != '$') lx.fail("expected a section such as $Nodes, found '" + std::string(tok) + "'");
    const std::string section(tok.substr(1));
    if (!haveFormat && section != "MeshFormat") lx.fail("the file does not start with $MeshFormat (not a Gmsh mesh?)");
    if (section == "MeshFormat") {
      readFormat(lx);
      haveFormat = true;
    } else if (section == "PhysicalNames") {
      readPhysicalNames(lx, d);
    } else if (section == "Entities") {
      readEntities(lx, d);
    } else if (section == "Nodes") {
      readNodes(lx, d);
      haveNodes = true;
    } else if (section == "Elements") {
      if (!haveNodes) lx.fail("$Elements before $Nodes");
      readElements(lx, d);
      haveElements = true;
    } else {
      lx.skipTo("$End" + section);  // $PartitionedEntities, $Periodic, $NodeData, $Comments, ...
    }
  }
  MFSI_CHECK(haveFormat, path << ": empty file (not a Gmsh mesh)");
  MFSI_CHECK(haveNodes && haveElements, path << ": no " << (haveNodes ? "$Elements" : "$Nodes") << " section");
  MFSI_CHECK(!d.hexes.empty(), path << ": no 8-node hexahedra (Gmsh element type 5) in the mesh");

  // Reject non-hex and inverted cells here, where the element tag and line are known.
  for (const auto& h : d.hexes) {
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < a; ++b)
        if (h.nodes[a] == h.nodes[b])
          lx.failAt(h.line, "non-hex cell: element " + std::to_string(h.tag) + " repeats node tag " +
                                std::to_string(d.nodeTag[h.nodes[a]]) + " (degenerate hexahedron)");
    double x[8][3];
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k) x[a][k] = d.coords[h.nodes[a]][k];
    const double jmin = geom::hexMinScaledJacobian(x);
    if (!(jmin > 0.0)) {
      std::ostringstream os;
      os << "element " << h.tag << " is an inverted or degenerate hexahedron (minimum scaled corner Jacobian " << jmin
         << " <= 0; check its node order)";
      lx.failAt(h.line, os.str());
    }
  }

  // Keep only the nodes of hexahedra, numbered in file order.
  std::vector<lid_t> newIndex(d.coords.size(), -1);
  for (const auto& h : d.hexes)
    for (const lid_t v : h.nodes) newIndex[v] = 0;
  HexMeshInput out;
  out.source = path;
  for (std::size_t v = 0; v < d.coords.size(); ++v)
    if (newIndex[v] == 0) {
      newIndex[v] = static_cast<lid_t>(out.points.size());
      out.points.push_back(d.coords[v]);
    }
  out.cells.reserve(d.hexes.size());
  for (const auto& h : d.hexes) {
    std::array<lid_t, 8> c;
    for (int a = 0; a < 8; ++a) c[a] = newIndex[h.nodes[a]];
    out.cells.push_back(c);
  }

  // One patch per physical name, in physical-tag order.
  std::map<int, std::size_t> patchOfPhysical;
  for (const auto& q : d.quads) patchOfPhysical.emplace(q.physical, 0);
  for (auto& [tag, index] : patchOfPhysical) {
    const auto named = d.surfaceNames.find(tag);
    const std::string name = named != d.surfaceNames.end() ? named->second : "patch" + std::to_string(tag);
    const auto same = std::find_if(out.patches.begin(), out.patches.end(),
                                   [&](const HexMeshInput::PatchSpec& p) { return p.name == name; });
    index = static_cast<std::size_t>(same - out.patches.begin());
    if (same == out.patches.end()) {
      HexMeshInput::PatchSpec p;
      p.name = name;
      out.patches.push_back(p);
    }
  }
  for (const auto& q : d.quads) {
    std::array<lid_t, 4> f;
    for (int a = 0; a < 4; ++a) {
      f[a] = newIndex[q.nodes[a]];
      if (f[a] < 0)
        lx.failAt(q.line, "boundary element " + std::to_string(q.tag) + " uses node tag " +
                              std::to_string(d.nodeTag[q.nodes[a]]) + ", which belongs to no hexahedron");
    }
    out.patches[patchOfPhysical[q.physical]].faces.push_back(f);
  }
  return out;
}

}  // namespace mfsi
