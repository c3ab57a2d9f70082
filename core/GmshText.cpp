#include "core/GmshText.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace mfsi::gmsh {

namespace {

bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

}  // namespace

// --- Lexer ------------------------------------------------------------------------------------

Lexer::Lexer(std::string path, std::string text, MessageStyle style)
    : path_(std::move(path)), text_(std::move(text)), style_(std::move(style)) {}

Lexer Lexer::fromFile(const std::string& path, MessageStyle style) {
  std::ifstream in(path, std::ios::binary);
  MFSI_CHECK(in, path << ": cannot open the " << style.fileKind);
  std::ostringstream ss;
  ss << in.rdbuf();
  return Lexer(path, ss.str(), std::move(style));
}

bool Lexer::atEnd() {
  skipSpace();
  return pos_ >= text_.size();
}

std::string_view Lexer::next(std::string_view what) {
  const int before = line_;
  skipSpace();
  const bool end = pos_ >= text_.size();
  tokenLine_ = end && style_.eofLine == EofLine::LastToken ? before : line_;
  if (end) fail("unexpected end of file while reading " + describe(what) + " (truncated file?)");
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
  return std::string_view(text_).substr(start, pos_ - start);
}

long long Lexer::integer(std::string_view what) {
  const std::string_view tok = next(what);
  long long v = 0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec != std::errc() || end != tok.data() + tok.size())
    fail("expected " + describe(what) + " (an integer), found '" + std::string(tok) + "'");
  return v;
}

int Lexer::count(std::string_view what) {
  const long long v = integer(what);
  if (v < 0 || v > 2147483647LL) fail(describe(what) + " " + std::to_string(v) + " is out of range");
  return static_cast<int>(v);
}

double Lexer::real(std::string_view what) {
  std::string_view tok = next(what);
  const std::string_view full = tok;
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);  // from_chars rejects a leading '+'
  double v = 0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec != std::errc() || end != tok.data() + tok.size())
    fail("expected " + describe(what) + " (a number), found '" + std::string(full) + "'");
  return v;
}

std::string Lexer::quoted(std::string_view what) {
  skipSpace();
  if (pos_ < text_.size() && text_[pos_] == '"') {
    tokenLine_ = line_;
    const std::size_t close = text_.find_first_of("\"\n", pos_ + 1);
    if (close == std::string::npos || text_[close] != '"') fail("unterminated quoted " + std::string(what));
    std::string s = text_.substr(pos_ + 1, close - pos_ - 1);
    pos_ = close + 1;
    return s;
  }
  return std::string(next(what));
}

void Lexer::expectLineEnd(std::string_view what) {
  while (pos_ < text_.size() && text_[pos_] != '\n' && isSpace(text_[pos_])) ++pos_;
  if (pos_ < text_.size() && text_[pos_] != '\n') {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
    fail("unexpected '" + text_.substr(start, pos_ - start) + "' after " + describe(what));
  }
}

void Lexer::skipLine() {
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
}

void Lexer::skipTo(const std::string& endToken) {
  while (next(endToken) != endToken) {
  }
}

void Lexer::expect(const std::string& token) {
  const std::string_view tok = next(style_.quoteExpectedKeyword ? "'" + token + "'" : token);
  if (tok != token) fail("expected '" + token + "', found '" + std::string(tok) + "'");
}

void Lexer::failAt(int line, const std::string& msg) const {
  throw InputError(SourceLocation{path_, line, 0, ""}, msg);
}

std::string Lexer::describe(std::string_view what) const {
  std::string s(what);
  if (element_ >= 0) s += " of element " + std::to_string(element_);
  return s;
}

void Lexer::skipSpace() {
  while (pos_ < text_.size() && isSpace(text_[pos_])) {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
}

// --- sections ---------------------------------------------------------------------------------

const std::vector<int>* MshData::physicalsOf(int dim, int tag) const {
  const auto it = entityPhysicals.find({dim, tag});
  return it != entityPhysicals.end() && !it->second.empty() ? &it->second : nullptr;
}

namespace {

void readFormat(Lexer& lx) {
  const std::string version(lx.next("the format version"));
  if (version != "4.1")
    lx.fail("MSH format version " + version + " is not supported; only MSH 4.1 ASCII is read (" +
            lx.style().versionHint + ")");
  const int fileType = lx.count("the file type (0 = ASCII, 1 = binary)");
  if (fileType != 0)
    lx.fail("binary MSH files are not supported; only MSH 4.1 ASCII is read (" + lx.style().binaryHint + ")");
  lx.count("the data size");
  lx.expect("$EndMeshFormat");
}

void readPhysicalNames(Lexer& lx, MshData& d) {
  const int n = lx.count("the number of physical names");
  d.physicalNamesLine = lx.line();
  for (int i = 0; i < n; ++i) {
    const int dim = lx.count("a physical group dimension");
    const int tag = static_cast<int>(lx.integer("a physical group tag"));
    d.physicalNames[{dim, tag}] = lx.quoted("physical group name");
  }
  lx.expect("$EndPhysicalNames");
}

void readEntities(Lexer& lx, MshData& d) {
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
      std::vector<int> phys(lx.count("the number of physical tags"));
      // Gmsh writes signed physical tags in rare cases (orientation); the group is |tag|.
      for (auto& p : phys) p = std::abs(static_cast<int>(lx.integer("a physical tag")));
      if (dim > 0) {
        const int nBound = lx.count("the number of bounding entities");
        for (int b = 0; b < nBound; ++b) lx.integer("a bounding entity tag");
      }
      d.entityPhysicals[{dim, tag}] = std::move(phys);
    }
  lx.expect("$EndEntities");
}

void readNodes(Lexer& lx, MshData& d) {
  const long long nBlocks = lx.integer("the number of node blocks");
  const long long nNodes = lx.integer("the number of nodes");
  if (nBlocks < 0 || nNodes < 0 || nNodes > 2147483647LL) lx.fail("bad $Nodes header");
  lx.integer("the minimum node tag");
  lx.integer("the maximum node tag");
  // A node takes at least 8 characters (its tag and 3 coordinates, each with a separator), so a
  // corrupt count cannot make us reserve more than the file could hold.
  const auto expected = static_cast<std::size_t>(std::min<long long>(nNodes, lx.remaining() / 8));
  d.coords.reserve(expected);
  d.nodeTag.reserve(expected);
  d.nodeIndex.reserve(expected);
  for (long long b = 0; b < nBlocks; ++b) {
    const int dim = lx.count("the entity dimension of a node block");
    lx.integer("the entity tag of a node block");
    const int parametric = lx.count("the parametric flag of a node block");
    const int n = lx.count("the number of nodes in a block");
    if (dim > 3) lx.fail("node block of dimension " + std::to_string(dim));
    const std::size_t first = d.coords.size();
    for (int i = 0; i < n; ++i) {
      const long long tag = lx.integer("a node tag");
      if (!d.nodeIndex.emplace(tag, static_cast<lid_t>(d.nodeTag.size())).second)
        lx.fail("node tag " + std::to_string(tag) + " appears twice");
      d.nodeTag.push_back(tag);
    }
    d.coords.resize(first + n);
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) d.coords[first + i][k] = lx.real("a node coordinate");
      // Parametric coordinates (u, v, w up to the entity dimension) follow; we do not need them.
      if (parametric)
        for (int k = 0; k < dim; ++k) lx.real("a parametric node coordinate");
    }
  }
  if (static_cast<long long>(d.coords.size()) != nNodes)
    lx.fail("the $Nodes header announces " + std::to_string(nNodes) + " nodes but its blocks hold " +
            std::to_string(d.coords.size()));
  lx.expect("$EndNodes");
}

void readElements(Lexer& lx, const ElementBlockReader& readBlock) {
  const long long nBlocks = lx.integer("the number of element blocks");
  const long long nElements = lx.integer("the number of elements");
  if (nBlocks < 0 || nElements < 0) lx.fail("bad $Elements header");
  lx.integer("the minimum element tag");
  lx.integer("the maximum element tag");
  long long seen = 0;
  for (long long b = 0; b < nBlocks; ++b) {
    ElementBlock block;
    block.dim = lx.count("the entity dimension of an element block");
    block.entity = static_cast<int>(lx.integer("the entity tag of an element block"));
    block.type = lx.count("the element type of an element block");
    block.size = lx.count("the number of elements in a block");
    block.line = lx.line();
    seen += block.size;
    if (block.dim > 3) lx.fail("element block of dimension " + std::to_string(block.dim));
    readBlock(block);
  }
  if (seen != nElements)
    lx.fail("the $Elements header announces " + std::to_string(nElements) + " elements but its blocks hold " +
            std::to_string(seen));
  lx.expect("$EndElements");
}

}  // namespace

void readMsh41(Lexer& lx, MshData& d, const ElementBlockReader& readBlock) {
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
      readElements(lx, readBlock);
      haveElements = true;
    } else {
      lx.skipTo("$End" + section);  // $PartitionedEntities, $Periodic, $NodeData, $Comments, ...
    }
  }
  MFSI_CHECK(haveFormat, lx.path() << ": empty file (not a Gmsh mesh)");
  MFSI_CHECK(haveNodes && haveElements, lx.path() << ": no " << (haveNodes ? "$Elements" : "$Nodes") << " section");
}

void skipElements(Lexer& lx, int n) {
  for (int i = 0; i < n; ++i) {
    lx.integer("an element tag");
    lx.skipLine();
  }
}

lid_t readElementNode(Lexer& lx, const MshData& d, long long elementTag, std::string_view what) {
  const long long tag = lx.integer(what);
  const auto it = d.nodeIndex.find(tag);
  if (it == d.nodeIndex.end())
    lx.fail("element " + std::to_string(elementTag) + " refers to unknown node tag " + std::to_string(tag));
  return it->second;
}

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
    case 8:
      return "3-node line";
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
    case 20:
      return "9-node triangle";
    case 21:
      return "10-node triangle";
    case 26:
      return "4-node line";
    default:
      return "element of type " + std::to_string(type);
  }
}

}  // namespace mfsi::gmsh
