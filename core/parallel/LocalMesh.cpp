#include "core/parallel/LocalMesh.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace mfsi {

namespace {

template <class V>
using HostMirror = decltype(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), std::declval<V>()));

/// Owned entries (sorted) then the others sorted by (owner, id): the local order of one rank.
void sortLocalOrder(std::vector<lid_t>& entities, const std::vector<int>& ownerOf, int rank) {
  std::sort(entities.begin(), entities.end(), [&](lid_t a, lid_t b) {
    const bool ao = ownerOf[a] == rank, bo = ownerOf[b] == rank;
    if (ao != bo) return ao;
    if (ownerOf[a] != ownerOf[b]) return ownerOf[a] < ownerOf[b];
    return a < b;
  });
}

/// Members grouped by a key in CSR form: group g's members are members[offsets[g] .. offsets[g + 1]),
/// in the order `each` gives them. `each(emit)` calls emit(group, member) for every pair; it runs
/// twice (counting, then filling).
struct Grouping {
  std::vector<lid_t> offsets, members;
};

template <class Each>
Grouping groupBy(lid_t nGroups, const Each& each) {
  Grouping g;
  g.offsets.assign(static_cast<std::size_t>(nGroups) + 1, 0);
  each([&g](lid_t group, lid_t) { ++g.offsets[group + 1]; });
  for (lid_t k = 0; k < nGroups; ++k) g.offsets[k + 1] += g.offsets[k];
  g.members.resize(g.offsets[nGroups]);
  std::vector<lid_t> fill(g.offsets.begin(), g.offsets.end() - 1);
  each([&](lid_t group, lid_t member) { g.members[fill[group]++] = member; });
  return g;
}

}  // namespace

/// The whole mesh on the host (without a copy where its memory is the host's) and every rank's
/// lists.
struct MeshDecomposition::Data {
  /// Every rank's list of one kind of entity (cells or nodes) and what each rank sends.
  struct RankLists {
    std::vector<int> owner;                    ///< per global entity
    std::vector<std::vector<lid_t>> local;     ///< per rank: owned, then ghosts by owner
    std::vector<lid_t> nOwned;                 ///< per rank
    /// Per rank: (receiving rank, local index of the owned entry sent), grouped by receiver
    /// (ascending) and in the receiver's ghost order within a group.
    std::vector<std::vector<std::pair<int, lid_t>>> sends;

    /// Owned counts and the send lists, from `local` (already in local order) and `owner`.
    void finish(lid_t nGlobal) {
      const int ranks = static_cast<int>(local.size());
      std::vector<lid_t> ownedIndex(static_cast<std::size_t>(nGlobal), -1);
      nOwned.assign(ranks, 0);
      for (int r = 0; r < ranks; ++r) {
        const auto& mine = local[r];
        while (nOwned[r] < static_cast<lid_t>(mine.size()) && owner[mine[nOwned[r]]] == r) {
          ownedIndex[mine[nOwned[r]]] = nOwned[r];
          ++nOwned[r];
        }
      }
      sends.assign(ranks, {});
      for (int q = 0; q < ranks; ++q)
        for (std::size_t i = nOwned[q]; i < local[q].size(); ++i) {
          const lid_t e = local[q][i];
          sends[owner[e]].emplace_back(q, ownedIndex[e]);
        }
    }

    HaloPlan plan(int rank) const {
      const int ranks = static_cast<int>(local.size());
      const auto& mine = local[rank];
      HaloPlan p;
      p.nLocal = static_cast<lid_t>(mine.size());
      p.nOwned = nOwned[rank];
      std::vector<lid_t> recvCount(ranks, 0), sendCount(ranks, 0);
      for (lid_t i = p.nOwned; i < p.nLocal; ++i) ++recvCount[owner[mine[i]]];
      for (const auto& s : sends[rank]) ++sendCount[s.first];
      p.sendOffsets.push_back(0);
      p.recvOffsets.push_back(0);
      std::size_t k = 0;
      for (int r = 0; r < ranks; ++r) {
        if (r == rank || (sendCount[r] == 0 && recvCount[r] == 0)) continue;
        p.neighbours.push_back(r);
        for (; k < sends[rank].size() && sends[rank][k].first == r; ++k) p.sendIndices.push_back(sends[rank][k].second);
        p.sendOffsets.push_back(static_cast<lid_t>(p.sendIndices.size()));
        p.recvOffsets.push_back(p.recvOffsets.back() + recvCount[r]);
      }
      return p;
    }
  };

  const HexMesh& global;
  int ranks = 1;
  lid_t nCells = 0, nNodes = 0, nInternal = 0;
  HostMirror<ConstReal3View> points;
  HostMirror<ConstHex8View> cellNodes;
  HostMirror<ConstQuad4View> faceNodes;
  HostMirror<ConstIndexView> owner, nodeEdgeOffsets;
  RankLists cells, nodes;
  std::vector<lid_t> boundaryOffsets, boundaryFaces;  ///< per cell, the boundary faces it owns
  std::vector<lid_t> cellLocal, nodeLocal;             ///< scratch: a global id's local index, or -1

  explicit Data(const HexMesh& g)
      : global(g),
        nCells(g.nCells()),
        nNodes(g.nNodes()),
        nInternal(g.nInternalFaces()),
        points(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.referencePoints())),
        cellNodes(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.cellNodes())),
        faceNodes(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceNodes())),
        owner(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceOwner())),
        nodeEdgeOffsets(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.nodeNodeOffsets())) {}
};

MeshDecomposition::MeshDecomposition(const HexMesh& global, const std::vector<int>& cellRank, int ranks,
                                     int ghostLayers)
    : d_(std::make_unique<Data>(global)) {
  MFSI_CHECK(ranks >= 1, "MeshDecomposition: " << ranks << " ranks");
  MFSI_CHECK(ghostLayers >= 1, "MeshDecomposition: ghostLayers must be >= 1 (got " << ghostLayers << ")");
  MFSI_CHECK(static_cast<lid_t>(cellRank.size()) == global.nCells(),
             "MeshDecomposition: " << cellRank.size() << " cell ranks for " << global.nCells() << " cells");
  Data& d = *d_;
  d.ranks = ranks;
  for (lid_t c = 0; c < d.nCells; ++c)
    MFSI_CHECK(cellRank[c] >= 0 && cellRank[c] < ranks, "MeshDecomposition: cell " << c << " has rank " << cellRank[c]);

  // Face adjacency of the internal faces.
  const auto neighbour = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.faceNeighbour());
  const Grouping adjacency = groupBy(d.nCells, [&](auto emit) {
    for (lid_t f = 0; f < d.nInternal; ++f) {
      emit(d.owner(f), neighbour(f));
      emit(neighbour(f), d.owner(f));
    }
  });
  const std::vector<lid_t>& adjOff = adjacency.offsets;
  const std::vector<lid_t>& adj = adjacency.members;

  // Every rank's cells: owned, then ghostLayers rings of face neighbours.
  d.cells.owner = cellRank;
  d.cells.local.assign(ranks, {});
  for (lid_t c = 0; c < d.nCells; ++c) d.cells.local[cellRank[c]].push_back(c);
  std::vector<int> mark(d.nCells, -1);
  for (int r = 0; r < ranks; ++r) {
    auto& cells = d.cells.local[r];
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
    sortLocalOrder(cells, cellRank, r);
  }
  d.cells.finish(d.nCells);

  // Node owners: the lowest rank among the cells that own a node; every rank's nodes.
  d.nodes.owner.assign(d.nNodes, ranks);
  for (lid_t c = 0; c < d.nCells; ++c)
    for (int k = 0; k < 8; ++k) {
      int& o = d.nodes.owner[d.cellNodes(c, k)];
      o = std::min(o, cellRank[c]);
    }
  d.nodes.local.assign(ranks, {});
  std::vector<int> nodeMark(d.nNodes, -1);
  for (int r = 0; r < ranks; ++r) {
    for (lid_t c : d.cells.local[r])
      for (int k = 0; k < 8; ++k) {
        const lid_t n = d.cellNodes(c, k);
        if (nodeMark[n] != r) {
          nodeMark[n] = r;
          d.nodes.local[r].push_back(n);
        }
      }
    sortLocalOrder(d.nodes.local[r], d.nodes.owner, r);
  }
  d.nodes.finish(d.nNodes);

  // The boundary faces (patches and baffle sides) by owner cell.
  const lid_t nFaces = global.nFaces();
  Grouping boundary = groupBy(d.nCells, [&](auto emit) {
    for (lid_t f = d.nInternal; f < nFaces; ++f) emit(d.owner(f), f);
  });
  d.boundaryOffsets = std::move(boundary.offsets);
  d.boundaryFaces = std::move(boundary.members);
  d.cellLocal.assign(d.nCells, -1);
  d.nodeLocal.assign(d.nNodes, -1);
}

MeshDecomposition::~MeshDecomposition() = default;

int MeshDecomposition::ranks() const { return d_->ranks; }

LocalMeshPart MeshDecomposition::part(int rank) {
  Data& d = *d_;
  MFSI_CHECK(rank >= 0 && rank < d.ranks, "MeshDecomposition: rank " << rank << " of " << d.ranks);
  LocalMeshPart part;
  part.rank = rank;
  part.ranks = d.ranks;
  part.cells = d.cells.plan(rank);
  part.nodes = d.nodes.plan(rank);

  // The rank's mesh input.
  const auto& cells = d.cells.local[rank];
  const auto& nodes = d.nodes.local[rank];
  for (std::size_t i = 0; i < nodes.size(); ++i) d.nodeLocal[nodes[i]] = static_cast<lid_t>(i);
  for (std::size_t i = 0; i < cells.size(); ++i) d.cellLocal[cells[i]] = static_cast<lid_t>(i);
  HexMeshInput& in = part.input;
  in.source = d.global.source() + " (rank " + std::to_string(rank) + " of " + std::to_string(d.ranks) + ")";
  in.defaultPatch = kProcessorPatch;
  in.nOwnedCells = part.cells.nOwned;
  in.nOwnedNodes = part.nodes.nOwned;
  in.points.reserve(nodes.size());
  in.nodeGlobalIds.reserve(nodes.size());
  for (lid_t n : nodes) {
    in.points.push_back({d.points(n, 0), d.points(n, 1), d.points(n, 2)});
    in.nodeGlobalIds.push_back(n);
  }
  in.cells.reserve(cells.size());
  in.cellGlobalIds.reserve(cells.size());
  for (lid_t c : cells) {
    std::array<lid_t, 8> cn;
    for (int k = 0; k < 8; ++k) cn[k] = d.nodeLocal[d.cellNodes(c, k)];
    in.cells.push_back(cn);
    in.cellGlobalIds.push_back(c);
  }
  auto localQuad = [&](lid_t f) {
    std::array<lid_t, 4> q;
    for (int k = 0; k < 4; ++k) q[k] = d.nodeLocal[d.faceNodes(f, k)];
    return q;
  };
  // The boundary faces of the part's cells, in the whole mesh's order (patch by patch).
  std::vector<lid_t> faces;
  for (lid_t c : cells) faces.insert(faces.end(), d.boundaryFaces.begin() + d.boundaryOffsets[c],
                                     d.boundaryFaces.begin() + d.boundaryOffsets[c + 1]);
  std::sort(faces.begin(), faces.end());
  const auto& patches = d.global.patches();
  auto facesOf = [&](const Patch& p) {
    return std::make_pair(std::lower_bound(faces.begin(), faces.end(), p.start),
                          std::lower_bound(faces.begin(), faces.end(), p.start + p.size));
  };
  for (const Patch& p : patches) {
    if (p.kind == PatchKind::BaffleSlave) continue;
    const auto [first, last] = facesOf(p);
    if (p.kind == PatchKind::BaffleMaster) {
      // The baffle's faces whose two cells are both here; a half-present face (a ghost's side)
      // falls to the processor patch.
      HexMeshInput::BaffleSpec b;
      const std::string suffix = "_master";
      b.name = p.name.size() > suffix.size() ? p.name.substr(0, p.name.size() - suffix.size()) : p.name;
      const Patch& slave = patches[p.pairedPatch];
      for (auto it = first; it != last; ++it)
        if (d.cellLocal[d.owner(slave.start + (*it - p.start))] >= 0) b.faces.push_back(localQuad(*it));
      in.baffles.push_back(std::move(b));
      continue;
    }
    HexMeshInput::PatchSpec ps;
    ps.name = p.name;
    ps.kind = p.kind;
    for (auto it = first; it != last; ++it) ps.faces.push_back(localQuad(*it));
    in.patches.push_back(std::move(ps));
  }

  // Every owned node's edges in the part's cells, against the whole mesh's.
  std::vector<std::vector<lid_t>> edges(static_cast<std::size_t>(part.nodes.nOwned));
  for (const auto& cn : in.cells)
    for (const auto& e : kHexEdges)
      for (int s = 0; s < 2; ++s)
        if (cn[e[s]] < part.nodes.nOwned) edges[cn[e[s]]].push_back(cn[e[1 - s]]);
  for (lid_t i = 0; i < part.nodes.nOwned; ++i) {
    auto& a = edges[i];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    const lid_t n = nodes[i];
    if (static_cast<lid_t>(a.size()) != d.nodeEdgeOffsets(n + 1) - d.nodeEdgeOffsets(n)) part.incompleteNode = n;
  }

  for (lid_t n : nodes) d.nodeLocal[n] = -1;
  for (lid_t c : cells) d.cellLocal[c] = -1;
  return part;
}

LocalMeshPart localMeshPart(const HexMesh& global, const std::vector<int>& cellRank, int ranks, int rank,
                            int ghostLayers) {
  MFSI_CHECK(ranks >= 1 && rank >= 0 && rank < ranks, "localMeshPart: rank " << rank << " of " << ranks);
  return MeshDecomposition(global, cellRank, ranks, ghostLayers).part(rank);
}

namespace {
using FaceKey = std::array<gid_t, 4>;
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
  const auto gnei = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.faceNeighbour());
  const auto gnid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.nodeGlobalIds());
  const auto gcid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), global.cellGlobalIds());
  // A face is one of its owner cell's faces (the part's owner is the global owner or, for a face
  // the part points the other way, its neighbour): each key is looked up among the faces of the
  // cell it names. A baffle's two sides share nodes but not a cell.
  const lid_t nCells = global.nCells(), nFaces = global.nFaces(), nInternal = global.nInternalFaces();
  gid_t maxCellId = -1;
  for (lid_t c = 0; c < nCells; ++c) maxCellId = std::max(maxCellId, gcid(c));
  std::vector<lid_t> cellOfId(static_cast<std::size_t>(maxCellId + 1), -1);
  for (lid_t c = 0; c < nCells; ++c) cellOfId[gcid(c)] = c;
  const Grouping byCell = groupBy(nCells, [&](auto emit) {
    for (lid_t f = 0; f < nFaces; ++f) {
      emit(gown(f), f);
      if (f < nInternal) emit(gnei(f), f);
    }
  });
  const std::vector<lid_t>& offsets = byCell.offsets;
  const std::vector<lid_t>& cellFaces = byCell.members;
  const std::size_t n = keys.size() / 5;
  std::vector<std::int64_t> ids(n);
  for (std::size_t f = 0; f < n; ++f) {
    const FaceKey k{keys[5 * f], keys[5 * f + 1], keys[5 * f + 2], keys[5 * f + 3]};
    const gid_t owner = keys[5 * f + 4];
    const lid_t c = owner >= 0 && owner <= maxCellId ? cellOfId[owner] : -1;
    lid_t g = -1;
    if (c >= 0)
      for (lid_t i = offsets[c]; i < offsets[c + 1] && g < 0; ++i)
        if (faceKey(gfn, cellFaces[i], gnid) == k) g = cellFaces[i];
    MFSI_CHECK(g >= 0, "globalFaceIds: face " << f << " of " << what << " is not in " << global.source());
    ids[f] = gown(g) == c ? g : -(static_cast<std::int64_t>(g) + 1);
  }
  return ids;
}

std::vector<std::int64_t> globalFaceIds(const HexMesh& part, const HexMesh& global) {
  return globalFaceIdsOfKeys(global, faceKeys(part), part.source());
}

}  // namespace mfsi
