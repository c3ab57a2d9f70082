#pragma once
/// \file
/// \brief A checkpoint written on one decomposition of the mesh, continued on another (another
/// rank count, or another partition of the same count).
///
/// Every rank of a run writes its modules' state into its own file, with its part's global ids
/// (PartIds). The arrays whose rows belong to cells, faces, boundary faces or nodes are tagged in
/// the file (io::Entity); to continue on another decomposition, each new rank reads every old
/// rank's file, assembles each tagged array by global id from the rows their owners wrote (a
/// face's flux turned to the face's global direction and back), and takes the rows of its own
/// part. Untagged values are the same on every rank (times, flags, the coupling's interface
/// vectors, the membranes) and are copied; arrays tagged `Part` (a matrix's values and what its
/// preconditioner was built from) are left out and rebuilt by the solver. The result is a file
/// in memory that the modules read as they read their own checkpoint.
///
/// What it costs: each new rank reads all of the old files and holds one whole-mesh array at a
/// time, O(global mesh) per rank, like the start-up of today's runs. The continued run is not
/// bitwise the uninterrupted one (sums run in another order, the preconditioner is built afresh);
/// it agrees to the solvers' tolerances.
#include "core/HexMesh.hpp"
#include "core/io/Checkpoint.hpp"
#include "core/io/Hdf5File.hpp"
#include "core/parallel/MeshScatter.hpp"

#include <cstdint>
#include <vector>

namespace mfsi::io {

/// \brief One rank's part as a checkpoint records it: the global id of each local entity, which
/// faces it owns, and the whole mesh's sizes.
struct PartIds {
  std::vector<std::int64_t> cells;  ///< per local cell (owned first)
  std::vector<std::int64_t> nodes;  ///< per local node (owned first)
  /// Per local face: the global face `g`, or `-(g + 1)` when the local face points the other way.
  std::vector<std::int64_t> faces;
  /// Per local face, 1 where this rank writes the face for everyone: the global face's owner cell
  /// is one of the rank's own cells (each global face has exactly one such rank).
  std::vector<std::int64_t> ownedFaces;
  long long ownedCells = 0, ownedNodes = 0, internalFaces = 0;
  long long globalCells = 0, globalNodes = 0, globalFaces = 0, globalInternalFaces = 0;
};

/// The ids of `part` (a rank's part of `global`, or `global` itself on one rank).
PartIds partIds(const HexMesh& part, const HexMesh& global);
/// The same from the global face of each of the part's faces (globalFaceIds) and the whole mesh's
/// counts: what a rank without the whole mesh knows.
PartIds partIds(const HexMesh& part, const std::vector<std::int64_t>& globalFaces, const MeshCounts& global);
/// The ids of the whole mesh as one rank's part (the identity): a one-rank run's checkpoint.
PartIds wholeMeshIds(const MeshCounts& global);
inline PartIds wholeMeshIds(const HexMesh& global) { return wholeMeshIds(MeshCounts::of(global)); }
/// Write / read PartIds under a group ("/run/part"); reading checks them against `global`'s sizes.
void writePartIds(StateWriter& w, const PartIds& ids);
PartIds readPartIds(const StateReader& r, const MeshCounts& global);

/// \brief Build in `out` every dataset under "/modules", and every tagged one under "/mesh" (the
/// moved points), of the part `mine` from the checkpoint in
/// `parts` (the old run's files, rank order) with their ids `old`. Throws InputError naming the
/// file and dataset when the files do not fit together (a missing dataset, a row count that is not
/// the part's, an untagged value that differs between ranks).
void redistribute(const std::vector<const Hdf5File*>& parts, const std::vector<PartIds>& old, const PartIds& mine,
                  Hdf5File& out);

}  // namespace mfsi::io
