#pragma once
/// \file
/// \brief A decomposed mesh handed out from one rank: the root reads the whole mesh and
/// partitions it, then sends every rank its part (core/parallel/LocalMesh), so no other rank
/// builds the whole mesh. What a part cannot tell by itself comes with it: the whole mesh's counts
/// (the sizes of the global numberings) and, on request, the global face each of its faces is.
///
/// The root computes the parts in one pass over the whole mesh (MeshDecomposition) and sends them
/// one after another; a parallel reader is what would remove the whole mesh from the root.
#include "core/HexMesh.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <mpi.h>

#include <cstdint>
#include <vector>

namespace mfsi {

/// \brief The sizes of a mesh's global numberings.
struct MeshCounts {
  long long cells = 0, nodes = 0, faces = 0, internalFaces = 0, boundaryFaces = 0, patches = 0;
  static MeshCounts of(const HexMesh& mesh);
};

/// \brief On `root`: every rank's part of `global` under `cellRank` (one entry per cell), sent to
/// its rank; on the others (`global` and `cellRank` unused): their part, received. Returns this
/// rank's part. Collective over `comm`.
LocalMeshPart scatterParts(MPI_Comm comm, int root, const HexMesh* global, const std::vector<int>& cellRank);

/// \brief globalFaceIds(part, global) for every rank's `part`, answered by `root`, which alone
/// holds `global` (the others pass null). Collective over `comm`.
std::vector<std::int64_t> globalFaceIdsFromRoot(MPI_Comm comm, int root, const HexMesh& part, const HexMesh* global);

/// \brief A part written to bytes and read back (what scatterParts sends).
std::vector<char> packPart(const LocalMeshPart& part);
LocalMeshPart unpackPart(const std::vector<char>& bytes);

}  // namespace mfsi
