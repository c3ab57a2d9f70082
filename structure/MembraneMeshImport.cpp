#include "structure/MembraneMeshImport.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace mfsi {

// --- baffles ----------------------------------------------------------------------------------

BaffleMembraneInput membraneMeshFromBaffle(const HexMesh& mesh, const std::string& baffleName) {
  ScopedRegion region("mfsi::structure::membraneMeshFromBaffle");
  const int master = mesh.findPatch(baffleName + "_master");
  if (master < 0 || mesh.patches()[master].kind != PatchKind::BaffleMaster) {
    std::string known;
    for (const auto& p : mesh.patches())
      if (p.kind == PatchKind::BaffleMaster)
        known += (known.empty() ? "" : ", ") + p.name.substr(0, p.name.size() - std::string("_master").size());
    MFSI_CHECK(false, mesh.source() << ": no baffle '" << baffleName << "' (baffles: "
                                    << (known.empty() ? "none" : known) << ")");
  }
  const Patch& pm = mesh.patches()[master];
  MFSI_CHECK(pm.pairedPatch >= 0, mesh.source() << ": baffle patch '" << pm.name << "' has no slave side");
  const Patch& ps = mesh.patches()[pm.pairedPatch];
  MFSI_CHECK(ps.size == pm.size, mesh.source() << ": baffle '" << baffleName << "' has " << pm.size
                                               << " master but " << ps.size << " slave faces");

  auto faces = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  auto points = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());

  BaffleMembraneInput out;
  out.mesh.source = mesh.source() + ": baffle '" + baffleName + "'";
  // Membrane node numbering: order of first use by the master faces, which keeps neighbours
  // close (the faces come sorted by node key) and needs no global node scan.
  std::unordered_map<lid_t, lid_t> local;
  for (lid_t f = pm.start; f < pm.start + pm.size; ++f) {
    std::array<lid_t, 4> q;
    for (int a = 0; a < 4; ++a) {
      const lid_t g = faces(f, a);
      auto [it, inserted] = local.emplace(g, static_cast<lid_t>(out.fluidNode.size()));
      if (inserted) {
        out.fluidNode.push_back(g);
        out.mesh.points.push_back({points(g, 0), points(g, 1), points(g, 2)});
      }
      q[a] = it->second;
    }
    out.mesh.elements.push_back(q);
    out.masterFace.push_back(f);
    out.slaveFace.push_back(ps.start + (f - pm.start));  // face i of one side pairs with face i of the other
  }
  return out;
}

// --- Gmsh surfaces ----------------------------------------------------------------------------

namespace {

std::string elementTypeName(long long type) {
  switch (type) {
    case 1: return "2-node line";
    case 2: return "3-node triangle";
    case 3: return "4-node quadrangle";
    case 8: return "3-node line";
    case 9: return "6-node triangle";
    case 10: return "9-node quadrangle";
    case 15: return "1-node point";
    case 16: return "8-node quadrangle";
    case 20: return "9-node triangle";
    case 21: return "10-node triangle";
    case 26: return "4-node line";
    default: return "element of type " + std::to_string(type);
  }
}

/// Whitespace-separated tokens with the line each sits on (same rules as core/GmshReader.cpp).
class Lexer {
 public:
  Lexer(std::string path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  bool atEnd() {
    skipSpace();
    return pos_ >= text_.size();
  }

  std::string_view next(const std::string& what) {
    const int previousLine = line_;  // the end of file is reported on the last line with content
    skipSpace();
    tokenLine_ = pos_ >= text_.size() ? previousLine : line_;
    if (pos_ >= text_.size()) fail("unexpected end of file while reading " + what + " (truncated file?)");
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
  }

  long long integer(const std::string& what) {
    const std::string_view tok = next(what);
    long long v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size())
      fail("expected " + what + " (an integer), found '" + std::string(tok) + "'");
    return v;
  }

  int count(const std::string& what) {
    const long long v = integer(what);
    if (v < 0 || v > 2147483647LL) fail(what + " " + std::to_string(v) + " is out of range");
    return static_cast<int>(v);
  }

  double number(const std::string& what) {
    std::string_view tok = next(what);
    const std::string full(tok);
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);  // from_chars rejects a leading '+'
    double v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size())
      fail("expected " + what + " (a number), found '" + full + "'");
    return v;
  }

  std::string quoted(const std::string& what) {
    skipSpace();
    if (pos_ < text_.size() && text_[pos_] == '"') {
      tokenLine_ = line_;
      const std::size_t close = text_.find_first_of("\"\n", pos_ + 1);
      if (close == std::string::npos || text_[close] != '"') fail("unterminated quoted " + what);
      std::string s = text_.substr(pos_ + 1, close - pos_ - 1);
      pos_ = close + 1;
      return s;
    }
    return std::string(next(what));
  }

  /// The rest of the line must be blank: catches elements with too many nodes.
  void expectLineEnd(const std::string& what) {
    while (pos_ < text_.size() && text_[pos_] != '\n' && isSpace(text_[pos_])) ++pos_;
    if (pos_ < text_.size() && text_[pos_] != '\n') {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
      fail("unexpected '" + text_.substr(start, pos_ - start) + "' after " + what);
    }
  }

  void skipLine() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }

  void skipTo(const std::string& endToken) {
    while (next(endToken) != endToken) {
    }
  }

  void expect(const std::string& token) {
    const std::string_view tok = next("'" + token + "'");
    if (tok != token) fail("expected '" + token + "', found '" + std::string(tok) + "'");
  }

  int line() const { return tokenLine_; }

  [[noreturn]] void fail(const std::string& msg) const { failAt(tokenLine_, msg); }
  [[noreturn]] void failAt(int line, const std::string& msg) const {
    throw InputError(SourceLocation{path_, line, 0, ""}, msg);
  }

 private:
  static bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
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
};

struct RawElement {
  std::array<lid_t, 4> nodes{-1, -1, -1, -1};  // indices into the file's node list
  int nNodes = 0;
  int dim = 0;
  int entity = 0;
  long long tag = 0;
  int line = 0;
};

using DimTag = std::pair<int, int>;

struct SurfaceData {
  std::map<DimTag, std::string> names;             // (dim, physical tag) -> name
  int namesLine = 0;                               // line of $PhysicalNames (0: none)
  std::map<DimTag, std::vector<int>> physicals;    // (dim, entity tag) -> physical tags
  std::vector<std::array<real, 3>> coords;
  std::vector<long long> nodeTag;
  std::unordered_map<long long, lid_t> nodeIndex;  // tag -> index into coords
  std::vector<RawElement> surface;                 // triangles and quadrangles
  std::vector<RawElement> marks;                   // lines and points of physical groups
};

void readFormat(Lexer& lx) {
  const std::string version(lx.next("the format version"));
  if (version != "4.1")
    lx.fail("MSH format version " + version +
            " is not supported; only MSH 4.1 ASCII is read (export with Gmsh's '-format msh41' option)");
  const int fileType = lx.count("the file type (0 = ASCII, 1 = binary)");
  if (fileType != 0) lx.fail("binary MSH files are not supported; only MSH 4.1 ASCII is read (Mesh.Binary = 0)");
  lx.count("the data size");
  lx.expect("$EndMeshFormat");
}

void readPhysicalNames(Lexer& lx, SurfaceData& d) {
  const int n = lx.count("the number of physical names");
  d.namesLine = lx.line();
  for (int i = 0; i < n; ++i) {
    const int dim = lx.count("a physical group dimension");
    const int tag = static_cast<int>(lx.integer("a physical group tag"));
    d.names[{dim, tag}] = lx.quoted("physical group name");
  }
  lx.expect("$EndPhysicalNames");
}

void readEntities(Lexer& lx, SurfaceData& d) {
  int n[4];
  n[0] = lx.count("the number of point entities");
  n[1] = lx.count("the number of curve entities");
  n[2] = lx.count("the number of surface entities");
  n[3] = lx.count("the number of volume entities");
  for (int dim = 0; dim < 4; ++dim)
    for (int e = 0; e < n[dim]; ++e) {
      const int tag = static_cast<int>(lx.integer("an entity tag"));
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) lx.number("an entity coordinate");
      std::vector<int> phys(lx.count("the number of physical tags"));
      for (auto& p : phys) p = std::abs(static_cast<int>(lx.integer("a physical tag")));
      if (dim > 0) {
        const int nBound = lx.count("the number of bounding entities");
        for (int b = 0; b < nBound; ++b) lx.integer("a bounding entity tag");
      }
      d.physicals[{dim, tag}] = std::move(phys);
    }
  lx.expect("$EndEntities");
}

void readNodes(Lexer& lx, SurfaceData& d) {
  const long long nBlocks = lx.integer("the number of node blocks");
  const long long nNodes = lx.integer("the number of nodes");
  if (nBlocks < 0 || nNodes < 0 || nNodes > 2147483647LL) lx.fail("bad $Nodes header");
  lx.integer("the minimum node tag");
  lx.integer("the maximum node tag");
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
      for (int k = 0; k < 3; ++k) d.coords[first + i][k] = lx.number("a node coordinate");
      if (parametric)
        for (int k = 0; k < dim; ++k) lx.number("a parametric node coordinate");
    }
  }
  if (static_cast<long long>(d.coords.size()) != nNodes)
    lx.fail("the $Nodes header announces " + std::to_string(nNodes) + " nodes but its blocks hold " +
            std::to_string(d.coords.size()));
  lx.expect("$EndNodes");
}

bool inPhysicalGroup(const SurfaceData& d, int dim, int entity) {
  const auto it = d.physicals.find({dim, entity});
  return it != d.physicals.end() && !it->second.empty();
}

void readElements(Lexer& lx, SurfaceData& d) {
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
    seen += n;
    if (dim > 3) lx.fail("element block of dimension " + std::to_string(dim));
    // Which blocks we keep: all surface elements; lines and points only in physical groups
    // (they become node sets); volume elements never.
    const bool keep = dim == 2 || ((dim == 0 || dim == 1) && inPhysicalGroup(d, dim, entity));
    if (!keep) {
      for (int i = 0; i < n; ++i) {
        lx.integer("an element tag");
        lx.skipLine();
      }
      continue;
    }
    int nNodes = 0;
    if (dim == 2 && (type == 2 || type == 3)) nNodes = type == 2 ? 3 : 4;
    if (dim == 1 && type == 1) nNodes = 2;
    if (dim == 0 && type == 15) nNodes = 1;
    if (nNodes == 0) {
      if (n == 0) continue;
      const long long tag = lx.integer("an element tag");
      lx.fail("unsupported element type: element " + std::to_string(tag) + " is a " + elementTypeName(type) +
              " (Gmsh element type " + std::to_string(type) + ") on a " + (dim == 2 ? "surface" : "physical") +
              " entity of dimension " + std::to_string(dim) +
              "; membrane meshes are made of 3-node triangles (type 2) and 4-node quadrangles (type 3), "
              "node sets of 2-node lines (type 1) and points (type 15)");
    }
    for (int i = 0; i < n; ++i) {
      RawElement e;
      e.tag = lx.integer("an element tag");
      e.line = lx.line();
      e.dim = dim;
      e.entity = entity;
      e.nNodes = nNodes;
      const std::string what = "the node tags of element " + std::to_string(e.tag);
      for (int a = 0; a < nNodes; ++a) {
        const long long tag = lx.integer(what);
        const auto it = d.nodeIndex.find(tag);
        if (it == d.nodeIndex.end())
          lx.fail("element " + std::to_string(e.tag) + " refers to unknown node tag " + std::to_string(tag));
        e.nodes[a] = it->second;
      }
      lx.expectLineEnd("the " + std::to_string(nNodes) + " node tags of element " + std::to_string(e.tag));
      for (int a = 0; a < nNodes; ++a)
        for (int c = 0; c < a; ++c)
          if (e.nodes[a] == e.nodes[c])
            lx.failAt(e.line, "element " + std::to_string(e.tag) + " repeats node tag " +
                                  std::to_string(d.nodeTag[e.nodes[a]]) + " (degenerate element)");
      (dim == 2 ? d.surface : d.marks).push_back(e);
    }
  }
  if (seen != nElements)
    lx.fail("the $Elements header announces " + std::to_string(nElements) + " elements but its blocks hold " +
            std::to_string(seen));
  lx.expect("$EndElements");
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  MFSI_CHECK(in, path << ": cannot open the Gmsh surface mesh file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Physical tag of the surface group called `group` (a name, or a tag given as a number); -1 when absent.
int findSurfaceGroup(const SurfaceData& d, const std::string& group) {
  for (const auto& [key, name] : d.names)
    if (key.first == 2 && name == group) return key.second;
  int tag = 0;
  const auto [end, ec] = std::from_chars(group.data(), group.data() + group.size(), tag);
  if (ec == std::errc() && end == group.data() + group.size())
    for (const auto& [key, phys] : d.physicals)
      if (key.first == 2 && std::find(phys.begin(), phys.end(), tag) != phys.end()) return tag;
  return -1;
}

}  // namespace

MembraneMeshInput readGmshSurface(const std::string& path, const std::string& physicalGroup) {
  ScopedRegion region("mfsi::structure::readGmshSurface");
  Lexer lx(path, readWholeFile(path));
  SurfaceData d;
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
      lx.skipTo("$End" + section);
    }
  }
  MFSI_CHECK(haveFormat, path << ": empty file (not a Gmsh mesh)");
  MFSI_CHECK(haveNodes && haveElements, path << ": no " << (haveNodes ? "$Elements" : "$Nodes") << " section");

  // Select the surface elements.
  std::vector<const RawElement*> chosen;
  if (physicalGroup.empty()) {
    for (const auto& e : d.surface) chosen.push_back(&e);
  } else {
    const int group = findSurfaceGroup(d, physicalGroup);
    if (group < 0) {
      std::set<std::string> known;
      for (const auto& [key, phys] : d.physicals)
        if (key.first == 2)
          for (int p : phys) {
            const auto named = d.names.find({2, p});
            known.insert(named != d.names.end() ? "'" + named->second + "'" : std::to_string(p));
          }
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      lx.failAt(d.namesLine, "no physical surface group '" + physicalGroup + "' (surface groups: " +
                                 (list.empty() ? "none" : list) + ")");
    }
    for (const auto& e : d.surface) {
      const auto& phys = d.physicals[{2, e.entity}];
      if (std::find(phys.begin(), phys.end(), group) != phys.end()) chosen.push_back(&e);
    }
    MFSI_CHECK(!chosen.empty(), path << ": physical surface group '" << physicalGroup
                                     << "' holds no triangles or quadrangles");
  }
  MFSI_CHECK(!chosen.empty(), path << ": no triangles (type 2) or quadrangles (type 3) in the mesh");

  // Keep only the nodes of the chosen elements, numbered in file order.
  std::vector<lid_t> newIndex(d.coords.size(), -1);
  for (const RawElement* e : chosen)
    for (int a = 0; a < e->nNodes; ++a) newIndex[e->nodes[a]] = 0;
  MembraneMeshInput out;
  out.source = physicalGroup.empty() ? path : path + " (surface '" + physicalGroup + "')";
  for (std::size_t v = 0; v < d.coords.size(); ++v)
    if (newIndex[v] == 0) {
      newIndex[v] = static_cast<lid_t>(out.points.size());
      out.points.push_back(d.coords[v]);
    }
  out.elements.reserve(chosen.size());
  for (const RawElement* e : chosen) {
    std::array<lid_t, 4> q{-1, -1, -1, -1};
    for (int a = 0; a < e->nNodes; ++a) q[a] = newIndex[e->nodes[a]];
    out.elements.push_back(q);
  }

  // Node sets from the lines and points of physical groups.
  std::map<std::string, std::set<lid_t>> sets;
  for (const auto& e : d.marks)
    for (int p : d.physicals[{e.dim, e.entity}]) {
      const auto named = d.names.find({e.dim, p});
      const std::string name =
          named != d.names.end() ? named->second : (e.dim == 1 ? "line" : "point") + std::to_string(p);
      auto& s = sets[name];
      for (int a = 0; a < e.nNodes; ++a)
        if (newIndex[e.nodes[a]] >= 0) s.insert(newIndex[e.nodes[a]]);
    }
  for (const auto& [name, nodes] : sets)
    if (!nodes.empty()) out.nodeSets[name] = std::vector<lid_t>(nodes.begin(), nodes.end());
  return out;
}

}  // namespace mfsi
