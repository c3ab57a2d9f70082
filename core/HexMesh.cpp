#include "core/HexMesh.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"
#include "core/Suggest.hpp"

#include <algorithm>
#include <map>
#include <numeric>

namespace mfsi {

const char* toString(PatchKind kind) {
  switch (kind) {
    case PatchKind::Patch: return "patch";
    case PatchKind::Wall: return "wall";
    case PatchKind::Symmetry: return "symmetry";
    case PatchKind::Empty: return "empty";
    case PatchKind::BaffleMaster: return "baffleMaster";
    case PatchKind::BaffleSlave: return "baffleSlave";
  }
  return "?";
}

int HexMesh::findPatch(const std::string& name) const {
  for (std::size_t i = 0; i < patches_.size(); ++i)
    if (patches_[i].name == name) return static_cast<int>(i);
  return -1;
}

int HexMesh::patchIndex(const std::string& name) const {
  const int i = findPatch(name);
  if (i >= 0) return i;
  throw InputError(source_ + ": " + noPatchMessage(name));
}

std::vector<std::string> HexMesh::patchNames() const {
  std::vector<std::string> names;
  for (const auto& p : patches_) names.push_back(p.name);
  return names;
}

std::string HexMesh::noPatchMessage(const std::string& name) const {
  const std::vector<std::string> names = patchNames();
  return "the mesh has no patch '" + name + "'" + didYouMean(name, names) + "; patches: " + joinList(names);
}

void HexMesh::resetPoints() const { Kokkos::deep_copy(points_, points0_); }

namespace {

using Quad = std::array<lid_t, 4>;

Quad sortedKey(const Quad& q) {
  Quad k = q;
  std::sort(k.begin(), k.end());
  return k;
}

struct CellFaceRef {
  Quad key;
  lid_t cell;
  int local;
};

template <class T, class HostArray>
void fillDevice(T& view, const HostArray& host) {
  auto h = Kokkos::create_mirror_view(view);
  for (std::size_t i = 0; i < host.size(); ++i) h(i) = host[i];
  Kokkos::deep_copy(view, h);
}

}  // namespace

HexMesh buildHexMesh(const HexMeshInput& in) {
  ScopedRegion region("mfsi::core::mesh::build");
  const std::string& src = in.source.empty() ? std::string("<mesh>") : in.source;
  const lid_t nNodes = static_cast<lid_t>(in.points.size());
  const lid_t nCells = static_cast<lid_t>(in.cells.size());
  MFSI_CHECK(nCells > 0, src << ": mesh has no cells");

  // --- validate cells: node ids, repeated nodes (non-hex), inverted/degenerate -----------------
  for (lid_t c = 0; c < nCells; ++c) {
    const auto& cn = in.cells[c];
    for (int a = 0; a < 8; ++a) {
      MFSI_CHECK(cn[a] >= 0 && cn[a] < nNodes,
                 src << ": cell " << c << " refers to node " << cn[a] << " but the mesh has " << nNodes << " nodes");
      for (int b = 0; b < a; ++b)
        MFSI_CHECK(cn[a] != cn[b], src << ": cell " << c << " is not a hexahedron (node " << cn[a]
                                       << " appears twice: degenerate prism/pyramid/tet cells are not supported)");
    }
    double x[8][3];
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k) x[a][k] = in.points[cn[a]][k];
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k)
        MFSI_CHECK(std::isfinite(x[a][k]), src << ": node " << cn[a] << " has a non-finite coordinate");
    const double jmin = geom::hexMinScaledJacobian(x);
    MFSI_CHECK(jmin > 0.0, src << ": cell " << c << " is inverted or degenerate (minimum scaled corner Jacobian "
                               << jmin << " <= 0; check its node order)");
  }

  // --- match cell faces ------------------------------------------------------------------------
  std::vector<CellFaceRef> refs;
  refs.reserve(static_cast<std::size_t>(nCells) * 6);
  for (lid_t c = 0; c < nCells; ++c)
    for (int f = 0; f < 6; ++f) {
      Quad q;
      for (int k = 0; k < 4; ++k) q[k] = in.cells[c][kHexFaces[f][k]];
      refs.push_back({sortedKey(q), c, f});
    }
  std::sort(refs.begin(), refs.end(), [](const CellFaceRef& a, const CellFaceRef& b) {
    return a.key != b.key ? a.key < b.key : a.cell < b.cell;
  });

  struct InternalFace {
    lid_t owner, neighbour;
    int ownerLocal;
  };
  std::vector<InternalFace> internal;
  std::map<Quad, std::pair<lid_t, int>> boundary;  // key -> (cell, local face)
  for (std::size_t i = 0; i < refs.size();) {
    std::size_t j = i + 1;
    while (j < refs.size() && refs[j].key == refs[i].key) ++j;
    MFSI_CHECK(j - i <= 2, src << ": a face of cell " << refs[i].cell << " is shared by " << (j - i)
                               << " cells (non-manifold mesh)");
    if (j - i == 2) {
      MFSI_CHECK(refs[i].cell != refs[i + 1].cell, src << ": cell " << refs[i].cell << " has two identical faces");
      internal.push_back({refs[i].cell, refs[i + 1].cell, refs[i].local});
    } else {
      boundary[refs[i].key] = {refs[i].cell, refs[i].local};
    }
    i = j;
  }

  // --- baffles: internal faces become two boundary faces --------------------------------------
  std::map<Quad, std::pair<int, Quad>> baffleFace;  // key -> (baffle index, declared quad)
  for (std::size_t b = 0; b < in.baffles.size(); ++b)
    for (const auto& q : in.baffles[b].faces) {
      const bool inserted = baffleFace.emplace(sortedKey(q), std::make_pair(static_cast<int>(b), q)).second;
      MFSI_CHECK(inserted, src << ": baffle '" << in.baffles[b].name << "' lists a face twice or shares it with another baffle");
    }

  // --- boundary faces -> patches ---------------------------------------------------------------
  std::map<Quad, int> claimed;  // key -> patch spec index
  for (std::size_t p = 0; p < in.patches.size(); ++p)
    for (const auto& q : in.patches[p].faces) {
      const Quad k = sortedKey(q);
      MFSI_CHECK(boundary.count(k), src << ": patch '" << in.patches[p].name << "' lists face (" << q[0] << " " << q[1]
                                        << " " << q[2] << " " << q[3] << ") which is not a boundary face of the mesh");
      const bool inserted = claimed.emplace(k, static_cast<int>(p)).second;
      MFSI_CHECK(inserted, src << ": boundary face (" << q[0] << " " << q[1] << " " << q[2] << " " << q[3]
                               << ") is claimed by two patches (second: '" << in.patches[p].name << "')");
    }

  // Output patch list: the declared patches, then the default patch, then baffle sides.
  std::vector<Patch> patches;
  for (const auto& ps : in.patches) patches.push_back({ps.name, ps.kind, 0, 0, -1});
  std::vector<std::vector<std::pair<lid_t, int>>> patchFaces(in.patches.size());
  std::vector<std::pair<lid_t, int>> defaultFaces;
  for (const auto& [key, cf] : boundary) {
    auto it = claimed.find(key);
    if (it != claimed.end()) {
      patchFaces[it->second].push_back(cf);
    } else {
      MFSI_CHECK(!in.defaultPatch.empty(), src << ": boundary face of cell " << cf.first << " belongs to no patch");
      defaultFaces.push_back(cf);
    }
  }
  if (!defaultFaces.empty()) {
    patches.push_back({in.defaultPatch, PatchKind::Wall, 0, 0, -1});
    patchFaces.push_back(defaultFaces);
  }

  // Internal faces that are baffles leave the internal list.
  std::vector<InternalFace> keptInternal;
  struct BaffleSide {
    std::vector<std::pair<lid_t, int>> master, slave;
  };
  std::vector<BaffleSide> baffleSides(in.baffles.size());
  std::size_t baffleFound = 0;
  for (const auto& f : internal) {
    Quad q;
    for (int k = 0; k < 4; ++k) q[k] = in.cells[f.owner][kHexFaces[f.ownerLocal][k]];
    auto it = baffleFace.find(sortedKey(q));
    if (it == baffleFace.end()) {
      keptInternal.push_back(f);
      continue;
    }
    ++baffleFound;
    // The owner's outward normal vs the declared normal decides which cell is the master side.
    const Quad& decl = it->second.second;
    double xo[4][3], xd[4][3], so[3], sd[3];
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) {
        xo[a][k] = in.points[q[a]][k];
        xd[a][k] = in.points[decl[a]][k];
      }
    geom::quadAreaVector(xo, so);
    geom::quadAreaVector(xd, sd);
    const bool ownerIsMaster = geom::dot(so, sd) > 0.0;
    // local face of the neighbour cell that matches
    int nbLocal = -1;
    for (int lf = 0; lf < 6 && nbLocal < 0; ++lf) {
      Quad qn;
      for (int k = 0; k < 4; ++k) qn[k] = in.cells[f.neighbour][kHexFaces[lf][k]];
      if (sortedKey(qn) == sortedKey(q)) nbLocal = lf;
    }
    auto& bs = baffleSides[it->second.first];
    const std::pair<lid_t, int> ownerSide{f.owner, f.ownerLocal}, nbSide{f.neighbour, nbLocal};
    bs.master.push_back(ownerIsMaster ? ownerSide : nbSide);
    bs.slave.push_back(ownerIsMaster ? nbSide : ownerSide);
  }
  MFSI_CHECK(baffleFound == baffleFace.size(),
             src << ": " << (baffleFace.size() - baffleFound) << " baffle face(s) are not internal faces of the mesh");
  for (std::size_t b = 0; b < in.baffles.size(); ++b) {
    const int m = static_cast<int>(patches.size());
    patches.push_back({in.baffles[b].name + "_master", PatchKind::BaffleMaster, 0, 0, m + 1});
    patches.push_back({in.baffles[b].name + "_slave", PatchKind::BaffleSlave, 0, 0, m});
    // Pair faces by a common order (the master's sorted key) so face i matches face i.
    std::vector<std::size_t> order(baffleSides[b].master.size());
    std::iota(order.begin(), order.end(), 0);
    auto keyOf = [&](const std::pair<lid_t, int>& cf) {
      Quad q;
      for (int k = 0; k < 4; ++k) q[k] = in.cells[cf.first][kHexFaces[cf.second][k]];
      return sortedKey(q);
    };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t c) {
      return keyOf(baffleSides[b].master[a]) < keyOf(baffleSides[b].master[c]);
    });
    std::vector<std::pair<lid_t, int>> ms, ss;
    for (auto i : order) {
      ms.push_back(baffleSides[b].master[i]);
      ss.push_back(baffleSides[b].slave[i]);
    }
    patchFaces.push_back(ms);
    patchFaces.push_back(ss);
  }

  // --- assemble face arrays ---------------------------------------------------------------------
  std::sort(keptInternal.begin(), keptInternal.end(), [](const InternalFace& a, const InternalFace& b) {
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  const lid_t nInternal = static_cast<lid_t>(keptInternal.size());
  lid_t nFaces = nInternal;
  for (const auto& pf : patchFaces) nFaces += static_cast<lid_t>(pf.size());

  std::vector<Quad> faceNodes(nFaces);
  std::vector<lid_t> owner(nFaces), neighbour(nFaces, -1), facePatch(nFaces, -1);
  for (lid_t f = 0; f < nInternal; ++f) {
    const auto& fi = keptInternal[f];
    for (int k = 0; k < 4; ++k) faceNodes[f][k] = in.cells[fi.owner][kHexFaces[fi.ownerLocal][k]];
    owner[f] = fi.owner;
    neighbour[f] = fi.neighbour;
  }
  lid_t next = nInternal;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    patches[p].start = next;
    patches[p].size = static_cast<lid_t>(patchFaces[p].size());
    for (const auto& [cell, local] : patchFaces[p]) {
      for (int k = 0; k < 4; ++k) faceNodes[next][k] = in.cells[cell][kHexFaces[local][k]];
      owner[next] = cell;
      facePatch[next] = static_cast<lid_t>(p);
      ++next;
    }
  }

  // --- CSR cell -> faces ------------------------------------------------------------------------
  std::vector<lid_t> cfOff(nCells + 1, 0), cf;
  for (lid_t f = 0; f < nFaces; ++f) {
    ++cfOff[owner[f] + 1];
    if (neighbour[f] >= 0) ++cfOff[neighbour[f] + 1];
  }
  for (lid_t c = 0; c < nCells; ++c) cfOff[c + 1] += cfOff[c];
  cf.resize(cfOff[nCells]);
  {
    std::vector<lid_t> fill(cfOff.begin(), cfOff.end() - 1);
    for (lid_t f = 0; f < nFaces; ++f) {
      cf[fill[owner[f]]++] = f;
      if (neighbour[f] >= 0) cf[fill[neighbour[f]]++] = f;
    }
  }

  // --- CSR node -> node along cell edges --------------------------------------------------------
  std::vector<std::vector<lid_t>> adj(nNodes);
  for (const auto& cn : in.cells)
    for (const auto& e : kHexEdges) {
      adj[cn[e[0]]].push_back(cn[e[1]]);
      adj[cn[e[1]]].push_back(cn[e[0]]);
    }
  std::vector<lid_t> nnOff(nNodes + 1, 0), nn;
  for (lid_t n = 0; n < nNodes; ++n) {
    auto& a = adj[n];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    nnOff[n + 1] = nnOff[n] + static_cast<lid_t>(a.size());
    nn.insert(nn.end(), a.begin(), a.end());
  }

  // --- device views ------------------------------------------------------------------------------
  HexMesh m;
  m.source_ = src;
  m.nInternalFaces_ = nInternal;
  MFSI_CHECK(in.cellGlobalIds.empty() || in.cellGlobalIds.size() == in.cells.size(),
             src << ": " << in.cellGlobalIds.size() << " cell global ids for " << nCells << " cells");
  MFSI_CHECK(in.nodeGlobalIds.empty() || in.nodeGlobalIds.size() == in.points.size(),
             src << ": " << in.nodeGlobalIds.size() << " node global ids for " << nNodes << " nodes");
  m.nOwnedCells_ = in.nOwnedCells >= 0 ? std::min(in.nOwnedCells, nCells) : nCells;
  m.nOwnedNodes_ = in.nOwnedNodes >= 0 ? std::min(in.nOwnedNodes, nNodes) : nNodes;
  m.patches_ = patches;
  m.points_ = Real3View("mfsi::core::mesh::points", nNodes);
  m.points0_ = Real3View("mfsi::core::mesh::points0", nNodes);
  {
    auto h = Kokkos::create_mirror_view(m.points_);
    for (lid_t n = 0; n < nNodes; ++n)
      for (int k = 0; k < 3; ++k) h(n, k) = in.points[n][k];
    Kokkos::deep_copy(m.points_, h);
    Kokkos::deep_copy(m.points0_, h);
  }
  m.cellNodes_ = Hex8View("mfsi::core::mesh::cellNodes", nCells);
  {
    auto h = Kokkos::create_mirror_view(m.cellNodes_);
    for (lid_t c = 0; c < nCells; ++c)
      for (int k = 0; k < 8; ++k) h(c, k) = in.cells[c][k];
    Kokkos::deep_copy(m.cellNodes_, h);
  }
  m.faceNodes_ = Quad4View("mfsi::core::mesh::faceNodes", nFaces);
  {
    auto h = Kokkos::create_mirror_view(m.faceNodes_);
    for (lid_t f = 0; f < nFaces; ++f)
      for (int k = 0; k < 4; ++k) h(f, k) = faceNodes[f][k];
    Kokkos::deep_copy(m.faceNodes_, h);
  }
  m.faceOwner_ = IndexView("mfsi::core::mesh::faceOwner", nFaces);
  m.faceNeighbour_ = IndexView("mfsi::core::mesh::faceNeighbour", nFaces);
  m.facePatch_ = IndexView("mfsi::core::mesh::facePatch", nFaces);
  m.cellFaceOffsets_ = IndexView("mfsi::core::mesh::cellFaceOffsets", nCells + 1);
  m.cellFaces_ = IndexView("mfsi::core::mesh::cellFaces", cf.size());
  m.nodeNodeOffsets_ = IndexView("mfsi::core::mesh::nodeNodeOffsets", nNodes + 1);
  m.nodeNodes_ = IndexView("mfsi::core::mesh::nodeNodes", nn.size());
  fillDevice(m.faceOwner_, owner);
  fillDevice(m.faceNeighbour_, neighbour);
  fillDevice(m.facePatch_, facePatch);
  fillDevice(m.cellFaceOffsets_, cfOff);
  fillDevice(m.cellFaces_, cf);
  fillDevice(m.nodeNodeOffsets_, nnOff);
  fillDevice(m.nodeNodes_, nn);
  m.cellGid_ = GlobalIndexView("mfsi::core::mesh::cellGid", nCells);
  m.nodeGid_ = GlobalIndexView("mfsi::core::mesh::nodeGid", nNodes);
  {
    auto hc = Kokkos::create_mirror_view(m.cellGid_);
    auto hn = Kokkos::create_mirror_view(m.nodeGid_);
    for (lid_t c = 0; c < nCells; ++c) hc(c) = in.cellGlobalIds.empty() ? c : in.cellGlobalIds[c];
    for (lid_t n = 0; n < nNodes; ++n) hn(n) = in.nodeGlobalIds.empty() ? n : in.nodeGlobalIds[n];
    Kokkos::deep_copy(m.cellGid_, hc);
    Kokkos::deep_copy(m.nodeGid_, hn);
  }
  return m;
}

}  // namespace mfsi
