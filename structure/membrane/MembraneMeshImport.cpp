#include "structure/membrane/MembraneMeshImport.hpp"

#include "core/Error.hpp"
#include "core/GmshText.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <map>
#include <set>
#include <unordered_map>

namespace mfsi {

// --- baffles ----------------------------------------------------------------------------------

namespace {

/// One quad per face of [first, first + count), nodes numbered in order of first use (which keeps
/// neighbours close: the faces come sorted by node key, and no global node scan is needed).
FluidSurfaceMembraneInput surfaceFromFaces(const HexMesh& mesh, lid_t first, lid_t count, const std::string& source) {
  auto faces = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  auto points = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.nodeGlobalIds());
  FluidSurfaceMembraneInput out;
  out.mesh.source = source;
  std::unordered_map<lid_t, lid_t> local;
  for (lid_t f = first; f < first + count; ++f) {
    std::array<lid_t, 4> q;
    for (int a = 0; a < 4; ++a) {
      const lid_t g = faces(f, a);
      auto [it, inserted] = local.emplace(g, static_cast<lid_t>(out.fluidNode.size()));
      if (inserted) {
        out.fluidNode.push_back(gid(g));
        out.mesh.points.push_back({points(g, 0), points(g, 1), points(g, 2)});
      }
      q[a] = it->second;
    }
    out.mesh.elements.push_back(q);
    out.masterFace.push_back(f);
    out.masterFaceNodes.push_back({gid(faces(f, 0)), gid(faces(f, 1)), gid(faces(f, 2)), gid(faces(f, 3))});
  }
  // Bounding-box side sets, for clamping the ends of a strip or the edges of a panel by name.
  std::array<real, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& p : out.mesh.points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  real span = 0;
  for (int k = 0; k < 3; ++k) span = std::max(span, hi[k] - lo[k]);
  const real tol = 1e-9 * span;
  const char* axis[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (!(hi[k] - lo[k] > tol)) continue;  // flat in this axis: both sides would be every node
    std::vector<lid_t>& smin = out.mesh.nodeSets[std::string(axis[k]) + "min"];
    std::vector<lid_t>& smax = out.mesh.nodeSets[std::string(axis[k]) + "max"];
    for (lid_t n = 0; n < static_cast<lid_t>(out.mesh.points.size()); ++n) {
      if (out.mesh.points[n][k] <= lo[k] + tol) smin.push_back(n);
      if (out.mesh.points[n][k] >= hi[k] - tol) smax.push_back(n);
    }
  }
  return out;
}

}  // namespace

FluidSurfaceMembraneInput membraneMeshFromBaffle(const HexMesh& mesh, const std::string& baffleName) {
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
  FluidSurfaceMembraneInput out =
      surfaceFromFaces(mesh, pm.start, pm.size, mesh.source() + ": baffle '" + baffleName + "'");
  auto faces = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.nodeGlobalIds());
  for (lid_t f = pm.start; f < pm.start + pm.size; ++f) {
    const lid_t s = ps.start + (f - pm.start);  // face i of one side pairs with face i of the other
    out.slaveFace.push_back(s);
    out.slaveFaceNodes.push_back({gid(faces(s, 0)), gid(faces(s, 1)), gid(faces(s, 2)), gid(faces(s, 3))});
  }
  return out;
}

FluidSurfaceMembraneInput membraneMeshFromPatch(const HexMesh& mesh, const std::string& patchName) {
  ScopedRegion region("mfsi::structure::membraneMeshFromPatch");
  const int pi = mesh.findPatch(patchName);
  const auto baffleSide = [](PatchKind k) { return k == PatchKind::BaffleMaster || k == PatchKind::BaffleSlave; };
  if (pi < 0 || baffleSide(mesh.patches()[pi].kind)) {
    std::string known;
    for (const auto& p : mesh.patches())
      if (!baffleSide(p.kind)) known += (known.empty() ? "" : ", ") + p.name;
    MFSI_CHECK(false, mesh.source() << ": no one-sided boundary patch '" << patchName << "' (patches: "
                                    << (known.empty() ? "none" : known) << ")");
  }
  const Patch& p = mesh.patches()[pi];
  MFSI_CHECK(p.size > 0, mesh.source() << ": patch '" << patchName << "' has no faces");
  return surfaceFromFaces(mesh, p.start, p.size, mesh.source() + ": patch '" + patchName + "'");
}

// --- Gmsh surfaces ----------------------------------------------------------------------------

namespace {

using gmsh::Lexer;

struct RawElement {
  std::array<lid_t, 4> nodes{-1, -1, -1, -1};  // indices into the file's node list
  int nNodes = 0;
  int dim = 0;
  int entity = 0;
  long long tag = 0;
  int line = 0;
};

/// The elements this reader keeps, in file order.
struct SurfaceElements {
  std::vector<RawElement> surface;  // triangles and quadrangles
  std::vector<RawElement> marks;    // lines and points of physical groups
};

/// This reader's messages, as they were before the MSH reading moved to core/GmshText.
gmsh::MessageStyle surfaceMessageStyle() {
  gmsh::MessageStyle style;
  style.fileKind = "Gmsh surface mesh file";
  style.eofLine = gmsh::EofLine::LastToken;
  style.quoteExpectedKeyword = true;
  style.versionHint = "export with Gmsh's '-format msh41' option";
  style.binaryHint = "Mesh.Binary = 0";
  return style;
}

void readSurfaceBlock(Lexer& lx, const gmsh::MshData& d, const gmsh::ElementBlock& block, SurfaceElements& el) {
  const int dim = block.dim, type = block.type, n = block.size;
  // Which blocks we keep: all surface elements; lines and points only in physical groups
  // (they become node sets); volume elements never.
  const bool keep = dim == 2 || ((dim == 0 || dim == 1) && d.physicalsOf(dim, block.entity));
  if (!keep) {
    gmsh::skipElements(lx, n);
    return;
  }
  int nNodes = 0;
  if (dim == 2 && (type == 2 || type == 3)) nNodes = type == 2 ? 3 : 4;
  if (dim == 1 && type == 1) nNodes = 2;
  if (dim == 0 && type == 15) nNodes = 1;
  if (nNodes == 0) {
    if (n == 0) return;
    const long long tag = lx.integer("an element tag");
    lx.fail("unsupported element type: element " + std::to_string(tag) + " is a " + gmsh::elementTypeName(type) +
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
    e.entity = block.entity;
    e.nNodes = nNodes;
    const std::string what = "the node tags of element " + std::to_string(e.tag);
    for (int a = 0; a < nNodes; ++a) e.nodes[a] = gmsh::readElementNode(lx, d, e.tag, what);
    lx.expectLineEnd("the " + std::to_string(nNodes) + " node tags of element " + std::to_string(e.tag));
    for (int a = 0; a < nNodes; ++a)
      for (int c = 0; c < a; ++c)
        if (e.nodes[a] == e.nodes[c])
          lx.failAt(e.line, "element " + std::to_string(e.tag) + " repeats node tag " +
                                std::to_string(d.nodeTag[e.nodes[a]]) + " (degenerate element)");
    (dim == 2 ? el.surface : el.marks).push_back(e);
  }
}

/// Physical tag of the surface group called `group` (a name, or a tag given as a number); -1 when absent.
int findSurfaceGroup(const gmsh::MshData& d, const std::string& group) {
  for (const auto& [key, name] : d.physicalNames)
    if (key.first == 2 && name == group) return key.second;
  int tag = 0;
  const auto [end, ec] = std::from_chars(group.data(), group.data() + group.size(), tag);
  if (ec == std::errc() && end == group.data() + group.size())
    for (const auto& [key, phys] : d.entityPhysicals)
      if (key.first == 2 && std::find(phys.begin(), phys.end(), tag) != phys.end()) return tag;
  return -1;
}

}  // namespace

MembraneMeshInput readGmshSurface(const std::string& path, const std::string& physicalGroup) {
  ScopedRegion region("mfsi::structure::readGmshSurface");
  Lexer lx = Lexer::fromFile(path, surfaceMessageStyle());
  gmsh::MshData d;
  SurfaceElements el;
  gmsh::readMsh41(lx, d, [&](const gmsh::ElementBlock& block) { readSurfaceBlock(lx, d, block, el); });

  // Select the surface elements.
  std::vector<const RawElement*> chosen;
  if (physicalGroup.empty()) {
    for (const auto& e : el.surface) chosen.push_back(&e);
  } else {
    const int group = findSurfaceGroup(d, physicalGroup);
    if (group < 0) {
      std::set<std::string> known;
      for (const auto& [key, phys] : d.entityPhysicals)
        if (key.first == 2)
          for (int p : phys) {
            const auto named = d.physicalNames.find({2, p});
            known.insert(named != d.physicalNames.end() ? "'" + named->second + "'" : std::to_string(p));
          }
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      lx.failAt(d.physicalNamesLine, "no physical surface group '" + physicalGroup +
                                         "' (surface groups: " + (list.empty() ? "none" : list) + ")");
    }
    for (const auto& e : el.surface) {
      const auto& phys = d.entityPhysicals[{2, e.entity}];
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
  for (const auto& e : el.marks)
    for (int p : d.entityPhysicals[{e.dim, e.entity}]) {
      const auto named = d.physicalNames.find({e.dim, p});
      const std::string name =
          named != d.physicalNames.end() ? named->second : (e.dim == 1 ? "line" : "point") + std::to_string(p);
      auto& s = sets[name];
      for (int a = 0; a < e.nNodes; ++a)
        if (newIndex[e.nodes[a]] >= 0) s.insert(newIndex[e.nodes[a]]);
    }
  for (const auto& [name, nodes] : sets)
    if (!nodes.empty()) out.nodeSets[name] = std::vector<lid_t>(nodes.begin(), nodes.end());
  return out;
}

}  // namespace mfsi
