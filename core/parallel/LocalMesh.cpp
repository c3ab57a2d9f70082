#include "core/parallel/LocalMesh.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <array>
#include <unordered_map>

namespace mfsi {

namespace {

/// Host copies of the global mesh's topology.
struct GlobalHost {
  lid_t nCells = 0, nNodes = 0, nInternal = 0;
  Kokkos::View<real* [3], Kokkos::HostSpace> points;
  Kokkos::View<lid_t* [8], Kokkos::HostSpace> cellNodes;
  Kokkos::View<lid_t* [4], Kokkos::HostSpace> faceNodes;
  Kokkos::View<lid_t*, Kokkos::HostSpace> owner, neighbour;
};

GlobalHost hostCopy(const HexMesh& m) {
  GlobalHost g;
  g.nCells = m.nCells();
  g.nNodes = m.nNodes();
  g.nInternal = m.nInternalFaces();
  g.points = Kokkos::View<real* [3], Kokkos::HostSpace>("mfsi::core::localMesh::points", g.nNodes);
  Kokkos::deep_copy(g.points, m.referencePoints());
  g.cellNodes = Kokkos::View<lid_t* [8], Kokkos::HostSpace>("mfsi::core::localMesh::cellNodes", g.nCells);
  Kokkos::deep_copy(g.cellNodes, m.cellNodes());
  g.faceNodes = Kokkos::View<lid_t* [4], Kokkos::HostSpace>("mfsi::core::localMesh::faceNodes", m.nFaces());
  Kokkos::deep_copy(g.faceNodes, m.faceNodes());
  g.owner = Kokkos::View<lid_t*, Kokkos::HostSpace>("mfsi::core::localMesh::owner", m.nFaces());
  Kokkos::deep_copy(g.owner, m.faceOwner());
  g.neighbour = Kokkos::View<lid_t*, Kokkos::HostSpace>("mfsi::core::localMesh::neighbour", m.nFaces());
  Kokkos::deep_copy(g.neighbour, m.faceNeighbour());
  return g;
}

/// Owned entries (sorted) then the others sorted by (owner, id): the local order of one rank.
std::vector<lid_t> localOrder(std::vector<lid_t> entities, const std::vector<int>& ownerOf, int rank) {
  std::sort(entities.begin(), entities.end(), [&](lid_t a, lid_t b) {
    const bool ao = ownerOf[a] == rank, bo = ownerOf[b] == rank;
    if (ao != bo) return ao;
    if (ownerOf[a] != ownerOf[b]) return ownerOf[a] < ownerOf[b];
    return a < b;
  });
  return entities;
}

/// The plan of `rank` given every rank's local list (owned first, then ghosts by owner).
HaloPlan makePlan(const std::vector<std::vector<lid_t>>& local, const std::vector<int>& ownerOf, int rank,
                  lid_t nGlobal) {
  const int ranks = static_cast<int>(local.size());
  const auto& mine = local[rank];
  HaloPlan p;
  p.nLocal = static_cast<lid_t>(mine.size());
  std::vector<lid_t> localIndex(nGlobal, -1);
  for (lid_t i = 0; i < p.nLocal; ++i) localIndex[mine[i]] = i;
  while (p.nOwned < p.nLocal && ownerOf[mine[p.nOwned]] == rank) ++p.nOwned;
  std::vector<lid_t> recvCount(ranks, 0);
  for (lid_t i = p.nOwned; i < p.nLocal; ++i) ++recvCount[ownerOf[mine[i]]];
  std::vector<std::vector<lid_t>> sends(ranks);
  for (int r = 0; r < ranks; ++r) {
    if (r == rank) continue;
    for (lid_t e : local[r])
      if (ownerOf[e] == rank) sends[r].push_back(localIndex[e]);
  }
  p.sendOffsets.push_back(0);
  p.recvOffsets.push_back(0);
  for (int r = 0; r < ranks; ++r) {
    if (r == rank || (sends[r].empty() && recvCount[r] == 0)) continue;
    p.neighbours.push_back(r);
    p.sendIndices.insert(p.sendIndices.end(), sends[r].begin(), sends[r].end());
    p.sendOffsets.push_back(static_cast<lid_t>(p.sendIndices.size()));
    p.recvOffsets.push_back(p.recvOffsets.back() + recvCount[r]);
  }
  return p;
}

}  // namespace

LocalMeshPart localMeshPart(const HexMesh& global, const std::vector<int>& cellRank, int ranks, int rank,
                            int ghostLayers) {
  MFSI_CHECK(ranks >= 1 && rank >= 0 && rank < ranks, "localMeshPart: rank " << rank << " of " << ranks);
  MFSI_CHECK(ghostLayers >= 1, "localMeshPart: ghostLayers must be >= 1 (got " << ghostLayers << ")");
  MFSI_CHECK(static_cast<lid_t>(cellRank.size()) == global.nCells(),
             "localMeshPart: " << cellRank.size() << " cell ranks for " << global.nCells() << " cells");
  const GlobalHost g = hostCopy(global);
  for (lid_t c = 0; c < g.nCells; ++c)
    MFSI_CHECK(cellRank[c] >= 0 && cellRank[c] < ranks, "localMeshPart: cell " << c << " has rank " << cellRank[c]);

  // Face adjacency of the internal faces.
  std::vector<lid_t> adjOff(g.nCells + 1, 0), adj;
  for (lid_t f = 0; f < g.nInternal; ++f) {
    ++adjOff[g.owner(f) + 1];
    ++adjOff[g.neighbour(f) + 1];
  }
  for (lid_t c = 0; c < g.nCells; ++c) adjOff[c + 1] += adjOff[c];
  adj.resize(adjOff[g.nCells]);
  {
    std::vector<lid_t> fill(adjOff.begin(), adjOff.end() - 1);
    for (lid_t f = 0; f < g.nInternal; ++f) {
      adj[fill[g.owner(f)]++] = g.neighbour(f);
      adj[fill[g.neighbour(f)]++] = g.owner(f);
    }
  }

  // Every rank's cells: owned, then ghostLayers rings of face neighbours.
  std::vector<std::vector<lid_t>> localCells(ranks);
  for (lid_t c = 0; c < g.nCells; ++c) localCells[cellRank[c]].push_back(c);
  std::vector<int> mark(g.nCells, -1);
  for (int r = 0; r < ranks; ++r) {
    auto& cells = localCells[r];
    for (lid_t c : cells) mark[c] = r;
    std::size_t begin = 0;
    for (int layer = 0; layer < ghostLayers; ++layer) {
      const std::size_t end = cells.size();
      for (std::size_t i = begin; i < end; ++i)
        for (lid_t k = adjOff[cells[i]]; k < adjOff[cells[i] + 1]; ++k)
          if (mark[adj[k]] != r) {
            mark[adj[k]] = r;
            cells.push_back(adj[k]);
          }
      begin = end;
    }
    cells = localOrder(cells, cellRank, r);
  }

  // Node owners: the lowest rank among the cells that own a node; every rank's nodes.
  std::vector<int> nodeRank(g.nNodes, ranks);
  for (lid_t c = 0; c < g.nCells; ++c)
    for (int k = 0; k < 8; ++k) nodeRank[g.cellNodes(c, k)] = std::min(nodeRank[g.cellNodes(c, k)], cellRank[c]);
  std::vector<std::vector<lid_t>> localNodes(ranks);
  std::vector<int> nodeMark(g.nNodes, -1);
  for (int r = 0; r < ranks; ++r) {
    for (lid_t c : localCells[r])
      for (int k = 0; k < 8; ++k) {
        const lid_t n = g.cellNodes(c, k);
        if (nodeMark[n] != r) {
          nodeMark[n] = r;
          localNodes[r].push_back(n);
        }
      }
    localNodes[r] = localOrder(localNodes[r], nodeRank, r);
  }

  LocalMeshPart part;
  part.rank = rank;
  part.ranks = ranks;
  part.cells = makePlan(localCells, cellRank, rank, g.nCells);
  part.nodes = makePlan(localNodes, nodeRank, rank, g.nNodes);

  // The rank's mesh input.
  const auto& cells = localCells[rank];
  const auto& nodes = localNodes[rank];
  std::vector<lid_t> nodeLocal(g.nNodes, -1), cellLocal(g.nCells, -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) nodeLocal[nodes[i]] = static_cast<lid_t>(i);
  for (std::size_t i = 0; i < cells.size(); ++i) cellLocal[cells[i]] = static_cast<lid_t>(i);
  HexMeshInput& in = part.input;
  in.source = global.source() + " (rank " + std::to_string(rank) + " of " + std::to_string(ranks) + ")";
  in.defaultPatch = kProcessorPatch;
  in.nOwnedCells = part.cells.nOwned;
  in.nOwnedNodes = part.nodes.nOwned;
  for (lid_t n : nodes) {
    in.points.push_back({g.points(n, 0), g.points(n, 1), g.points(n, 2)});
    in.nodeGlobalIds.push_back(n);
  }
  for (lid_t c : cells) {
    std::array<lid_t, 8> cn;
    for (int k = 0; k < 8; ++k) cn[k] = nodeLocal[g.cellNodes(c, k)];
    in.cells.push_back(cn);
    in.cellGlobalIds.push_back(c);
  }
  auto localQuad = [&](lid_t f) {
    std::array<lid_t, 4> q;
    for (int k = 0; k < 4; ++k) q[k] = nodeLocal[g.faceNodes(f, k)];
    return q;
  };
  const auto& patches = global.patches();
  for (const Patch& p : patches) {
    if (p.kind == PatchKind::BaffleSlave) continue;
    if (p.kind == PatchKind::BaffleMaster) {
      // The baffle's faces whose two cells are both here; a half-present face (a ghost's side)
      // falls to the processor patch.
      HexMeshInput::BaffleSpec b;
      const std::string suffix = "_master";
      b.name = p.name.size() > suffix.size() ? p.name.substr(0, p.name.size() - suffix.size()) : p.name;
      const Patch& slave = patches[p.pairedPatch];
      for (lid_t i = 0; i < p.size; ++i) {
        const lid_t fm = p.start + i, fs = slave.start + i;
        if (cellLocal[g.owner(fm)] >= 0 && cellLocal[g.owner(fs)] >= 0) b.faces.push_back(localQuad(fm));
      }
      in.baffles.push_back(std::move(b));
      continue;
    }
    HexMeshInput::PatchSpec ps;
    ps.name = p.name;
    ps.kind = p.kind;
    for (lid_t f = p.start; f < p.start + p.size; ++f)
      if (cellLocal[g.owner(f)] >= 0) ps.faces.push_back(localQuad(f));
    in.patches.push_back(std::move(ps));
  }

  // Every owned node's edges in the part's cells, against the whole mesh's.
  std::vector<std::vector<lid_t>> edges(static_cast<std::size_t>(part.nodes.nOwned));
  for (const auto& cn : in.cells)
    for (const auto& e : kHexEdges)
      for (int s = 0; s < 2; ++s)
        if (cn[e[s]] < part.nodes.nOwned) edges[cn[e[s]]].push_back(cn[e[1 - s]]);
  auto wholeEdges = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.nodeNodeOffsets());
  for (lid_t i = 0; i < part.nodes.nOwned; ++i) {
    auto& a = edges[i];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    const lid_t n = nodes[i];
    if (static_cast<lid_t>(a.size()) != wholeEdges(n + 1) - wholeEdges(n)) part.incompleteNode = n;
  }
  return part;
}

namespace {
using FaceKey = std::array<gid_t, 4>;
struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = 1469598103934665603ull;
    for (gid_t v : k) h = (h ^ static_cast<std::size_t>(v)) * 1099511628211ull;
    return h;
  }
};
template <class Quads, class Gids>
FaceKey faceKey(const Quads& fn, lid_t f, const Gids& nodeGid) {
  FaceKey k{nodeGid(fn(f, 0)), nodeGid(fn(f, 1)), nodeGid(fn(f, 2)), nodeGid(fn(f, 3))};
  std::sort(k.begin(), k.end());
  return k;
}
}  // namespace

std::vector<gid_t> faceKeys(const HexMesh& part) {
  const auto pfn = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.faceNodes());
  const auto pown = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.faceOwner());
  const auto pnid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.nodeGlobalIds());
  const auto pcid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.cellGlobalIds());
  std::vector<gid_t> keys;
  keys.reserve(static_cast<std::size_t>(part.nFaces()) * 5);
  for (lid_t f = 0; f < part.nFaces(); ++f) {
    const FaceKey k = faceKey(pfn, f, pnid);
    keys.insert(keys.end(), k.begin(), k.end());
    keys.push_back(pcid(pown(f)));
  }
  return keys;
}

std::vector<std::int64_t> globalFaceIdsOfKeys(const HexMesh& global, const std::vector<gid_t>& keys,
                                              const std::string& what) {
  const auto gfn = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.faceNodes());
  const auto gown = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.faceOwner());
  const auto gnid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.nodeGlobalIds());
  const auto gcid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.cellGlobalIds());
  // A face's nodes name it, but for a baffle's two sides: those share nodes and differ in owner.
  std::unordered_map<FaceKey, std::array<lid_t, 2>, FaceKeyHash> byNodes;
  byNodes.reserve(static_cast<std::size_t>(global.nFaces()));
  for (lid_t f = 0; f < global.nFaces(); ++f) {
    auto [it, fresh] = byNodes.try_emplace(faceKey(gfn, f, gnid), std::array<lid_t, 2>{f, -1});
    if (!fresh) it->second[1] = f;
  }
  const std::size_t n = keys.size() / 5;
  std::vector<std::int64_t> ids(n);
  for (std::size_t f = 0; f < n; ++f) {
    const FaceKey k{keys[5 * f], keys[5 * f + 1], keys[5 * f + 2], keys[5 * f + 3]};
    const auto it = byNodes.find(k);
    MFSI_CHECK(it != byNodes.end(), "globalFaceIds: face " << f << " of " << what << " is not in " << global.source());
    const gid_t owner = keys[5 * f + 4];
    lid_t g = it->second[0];
    if (it->second[1] >= 0 && gcid(gown(g)) != owner) g = it->second[1];  // the baffle's other side
    ids[f] = gcid(gown(g)) == owner ? g : -(static_cast<std::int64_t>(g) + 1);
  }
  return ids;
}

std::vector<std::int64_t> globalFaceIds(const HexMesh& part, const HexMesh& global) {
  return globalFaceIdsOfKeys(global, faceKeys(part), part.source());
}

}  // namespace mfsi
