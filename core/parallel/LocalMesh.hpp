#pragma once
/// \file
/// \brief One rank's part of a decomposed mesh: its owned cells, a layer (or more) of ghost cells
/// around them, the nodes of both, and the halo plans that say which owned entries each
/// neighbour rank needs and where the ghosts' values arrive.
///
/// Ordering (what the halo exchange relies on): owned cells first, in global-id order, then the
/// ghosts grouped by their owner rank (ascending) and in global-id order within a group, so the
/// values from one neighbour land in one contiguous range. Nodes likewise: a node belongs to the
/// lowest rank whose owned cells use it. A ghost cell's face that leads out of the rank's cells
/// goes to the patch "processor". The parts come from the whole mesh and its partition, with no
/// communication: MeshDecomposition makes every rank's part in one pass over the whole mesh (what
/// the rank that reads the mesh does before it hands the parts out).
#include "core/HexMesh.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mfsi {

/// Name of the patch that collects a part's faces leading to cells of other ranks.
inline constexpr const char* kProcessorPatch = "processor";

/// \brief Who sends what to whom, for one kind of entity (cells or nodes) on one rank.
struct HaloPlan {
  std::vector<int> neighbours;      ///< ranks exchanged with, ascending
  std::vector<lid_t> sendOffsets;   ///< per neighbour, into sendIndices (size neighbours + 1)
  std::vector<lid_t> sendIndices;   ///< local indices of owned entries, in the receiver's order
  std::vector<lid_t> recvOffsets;   ///< per neighbour: ghost range [nOwned + recvOffsets[k], nOwned + recvOffsets[k+1])
  lid_t nOwned = 0;
  lid_t nLocal = 0;                 ///< owned + ghosts
};

/// \brief One rank's mesh and its two halo plans.
struct LocalMeshPart {
  int rank = 0;
  int ranks = 1;
  HexMeshInput input;   ///< to build the rank's HexMesh (global ids and owned counts filled)
  HaloPlan cells;
  HaloPlan nodes;
  /// An owned node some of whose mesh edges lie only in cells the part lacks (cells that meet the
  /// rank's cells at that node alone), by global id (the largest), or -1. Node-to-node work (the
  /// mesh smoothing) needs every owned node's edges.
  gid_t incompleteNode = -1;
};

/// \brief Every rank's part of `global` under `cellRank` (one entry per global cell), with
/// `ghostLayers` layers of face-neighbour ghost cells (>= 1).
///
/// The work over the whole mesh (its face adjacency, every rank's cell and node lists, the node
/// owners, who sends what to whom) is done once, at construction; part(rank) then takes time in
/// proportion to the part, so handing out N parts costs one pass over the mesh, not N. `global`
/// must outlive the decomposition.
class MeshDecomposition {
 public:
  MeshDecomposition(const HexMesh& global, const std::vector<int>& cellRank, int ranks, int ghostLayers = 1);
  ~MeshDecomposition();
  MeshDecomposition(const MeshDecomposition&) = delete;
  MeshDecomposition& operator=(const MeshDecomposition&) = delete;

  int ranks() const;
  /// The part of `rank` (not const: it reuses scratch maps the size of the whole mesh).
  LocalMeshPart part(int rank);

 private:
  struct Data;
  std::unique_ptr<Data> d_;
};

/// \brief The part of `global` that `rank` holds: MeshDecomposition(...).part(rank), for a caller
/// that needs one part.
LocalMeshPart localMeshPart(const HexMesh& global, const std::vector<int>& cellRank, int ranks, int rank,
                            int ghostLayers = 1);

/// \brief The global face of `global` that each face of `part` is (`part`: a rank's part of it,
/// with its cells' and nodes' global ids; or `global` itself): `g` when the two point the same way
/// (the same owner cell), `-(g + 1)` when the part's face points the other way. A face of the
/// processor patch is the global internal face it lies on; a baffle's side, the side of the same
/// cell. Matched by the faces' global node ids, on the host.
std::vector<std::int64_t> globalFaceIds(const HexMesh& part, const HexMesh& global);

/// \brief What names each face of `part` for globalFaceIdsOfKeys: its nodes' global ids (sorted)
/// and its owner cell's global id, 5 values per face.
std::vector<gid_t> faceKeys(const HexMesh& part);
/// \brief globalFaceIds of faces given by their keys (`what` names them in messages).
std::vector<std::int64_t> globalFaceIdsOfKeys(const HexMesh& global, const std::vector<gid_t>& keys,
                                              const std::string& what);

}  // namespace mfsi
