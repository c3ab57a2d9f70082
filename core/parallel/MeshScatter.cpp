#include "core/parallel/MeshScatter.hpp"

#include "core/Error.hpp"
#include "core/parallel/ByteBuffer.hpp"

#include <limits>
#include <numeric>

namespace mfsi {

namespace {

constexpr int kPartTag = 7311;

void packPlan(const HaloPlan& p, ByteWriter& w) {
  w.vector(p.neighbours);
  w.vector(p.sendOffsets);
  w.vector(p.sendIndices);
  w.vector(p.recvOffsets);
  w.value(p.nOwned);
  w.value(p.nLocal);
}

HaloPlan unpackPlan(ByteReader& r) {
  HaloPlan p;
  r.vector(p.neighbours);
  r.vector(p.sendOffsets);
  r.vector(p.sendIndices);
  r.vector(p.recvOffsets);
  p.nOwned = r.value<lid_t>();
  p.nLocal = r.value<lid_t>();
  return p;
}

}  // namespace

MeshCounts MeshCounts::of(const HexMesh& mesh) {
  MeshCounts c;
  c.cells = mesh.nCells();
  c.nodes = mesh.nNodes();
  c.faces = mesh.nFaces();
  c.internalFaces = mesh.nInternalFaces();
  c.boundaryFaces = mesh.nBoundaryFaces();
  c.patches = static_cast<long long>(mesh.patches().size());
  return c;
}

std::vector<char> packPart(const LocalMeshPart& part) {
  ByteWriter w;
  w.value(part.rank);
  w.value(part.ranks);
  w.value(part.incompleteNode);
  packPlan(part.cells, w);
  packPlan(part.nodes, w);
  const HexMeshInput& in = part.input;
  w.string(in.source);
  w.string(in.defaultPatch);
  w.vector(in.points);
  w.vector(in.cells);
  w.count(in.patches.size());
  for (const auto& p : in.patches) {
    w.string(p.name);
    w.value(p.kind);
    w.vector(p.faces);
  }
  w.count(in.baffles.size());
  for (const auto& b : in.baffles) {
    w.string(b.name);
    w.vector(b.faces);
  }
  w.vector(in.cellGlobalIds);
  w.vector(in.nodeGlobalIds);
  w.value(in.nOwnedCells);
  w.value(in.nOwnedNodes);
  return std::move(w.bytes());
}

LocalMeshPart unpackPart(const std::vector<char>& bytes) {
  ByteReader r(bytes);
  LocalMeshPart part;
  part.rank = r.value<int>();
  part.ranks = r.value<int>();
  part.incompleteNode = r.value<gid_t>();
  part.cells = unpackPlan(r);
  part.nodes = unpackPlan(r);
  HexMeshInput& in = part.input;
  in.source = r.string();
  in.defaultPatch = r.string();
  r.vector(in.points);
  r.vector(in.cells);
  in.patches.resize(r.count());
  for (auto& p : in.patches) {
    p.name = r.string();
    p.kind = r.value<PatchKind>();
    r.vector(p.faces);
  }
  in.baffles.resize(r.count());
  for (auto& b : in.baffles) {
    b.name = r.string();
    r.vector(b.faces);
  }
  r.vector(in.cellGlobalIds);
  r.vector(in.nodeGlobalIds);
  in.nOwnedCells = r.value<lid_t>();
  in.nOwnedNodes = r.value<lid_t>();
  MFSI_CHECK(r.done(), "mesh part: " << bytes.size() << " bytes received, not all read");
  return part;
}

LocalMeshPart scatterParts(MPI_Comm comm, int root, const HexMesh* global, const std::vector<int>& cellRank) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  if (rank != root) {
    std::uint64_t size = 0;
    MPI_Recv(&size, 1, MPI_UINT64_T, root, kPartTag, comm, MPI_STATUS_IGNORE);
    std::vector<char> bytes(size);
    MPI_Recv(bytes.data(), static_cast<int>(size), MPI_CHAR, root, kPartTag, comm, MPI_STATUS_IGNORE);
    return unpackPart(bytes);
  }
  MFSI_CHECK(global != nullptr, "scatterParts: the root has no mesh");
  MeshDecomposition decomposition(*global, cellRank, ranks);
  LocalMeshPart mine;
  for (int r = 0; r < ranks; ++r) {
    LocalMeshPart part = decomposition.part(r);
    if (r == root) {
      mine = std::move(part);
      continue;
    }
    const std::vector<char> bytes = packPart(part);
    MFSI_CHECK(bytes.size() < static_cast<std::size_t>(std::numeric_limits<int>::max()),
               "scatterParts: rank " << r << "'s part is " << bytes.size() << " bytes, more than one message holds");
    const std::uint64_t size = bytes.size();
    MPI_Send(&size, 1, MPI_UINT64_T, r, kPartTag, comm);
    MPI_Send(bytes.data(), static_cast<int>(size), MPI_CHAR, r, kPartTag, comm);
  }
  return mine;
}

std::vector<std::int64_t> globalFaceIdsFromRoot(MPI_Comm comm, int root, const HexMesh& part, const HexMesh* global) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  const std::vector<gid_t> keys = faceKeys(part);
  const int n = static_cast<int>(keys.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(static_cast<std::size_t>(ranks));
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm);
  std::vector<gid_t> all;
  if (rank == root) {
    std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
    all.resize(static_cast<std::size_t>(offsets.back()) + static_cast<std::size_t>(counts.back()));
  }
  static_assert(sizeof(gid_t) == sizeof(std::int64_t), "gid_t is sent as MPI_INT64_T");
  MPI_Gatherv(keys.data(), n, MPI_INT64_T, all.data(), counts.data(), offsets.data(), MPI_INT64_T, root, comm);
  std::vector<std::int64_t> ids, allIds;
  std::vector<int> idCounts, idOffsets;
  if (rank == root) {
    MFSI_CHECK(global != nullptr, "globalFaceIdsFromRoot: the root has no mesh");
    allIds = globalFaceIdsOfKeys(*global, all, "a rank's part");
    for (int r = 0; r < ranks; ++r) {
      idCounts.push_back(counts[r] / 5);
      idOffsets.push_back(offsets[r] / 5);
    }
  }
  ids.resize(keys.size() / 5);
  MPI_Scatterv(allIds.data(), idCounts.data(), idOffsets.data(), MPI_INT64_T, ids.data(), static_cast<int>(ids.size()),
               MPI_INT64_T, root, comm);
  return ids;
}

}  // namespace mfsi
