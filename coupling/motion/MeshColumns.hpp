#pragma once
/// \file
/// \brief The columns of the mesh motion (MeshSmootherOptions::columns): the lines of cell edges
/// that leave a membrane node (its foot) and run layer by layer to another boundary node. Each
/// interior node of a column moves with its foot, by a factor falling linearly in reference arc
/// length from 1 at the foot to 0 at the far end.
///
/// On a decomposed mesh a line is traced by the rank that owns the node it has reached (an owned
/// node's edges are all on its rank) and handed to the owner of the next node when that one is a
/// ghost, so the search needs no rank to hold more than its part. Every line is traced on its own;
/// a line that shares a node with an earlier one (in the order of the feet) that was kept is left
/// to the Laplacian, so the columns are the same on any number of ranks.
#include "core/Types.hpp"

#include <mpi.h>

#include <vector>

namespace mfsi::coupling {

/// \brief One rank's part of the mesh as the column search sees it (host copies). Owned nodes
/// come first; the flags must agree on every copy of a shared node.
struct ColumnGraph {
  std::vector<lid_t> offsets, neighbours;  ///< node -> node edges (CSR), complete for owned nodes
  std::vector<double> points;              ///< reference positions, 3 per node
  std::vector<char> fixed;                 ///< prescribed nodes (boundary nodes: a line ends there)
  std::vector<char> sliding;               ///< sliding nodes (a line that meets one is dropped)
  std::vector<gid_t> gid;                  ///< global id of each local node
  lid_t nOwned = 0;
  std::vector<int> ghostOwner;             ///< the owner rank of ghost node nOwned + k
  MPI_Comm comm = MPI_COMM_NULL;           ///< null: the whole mesh on one rank
};

/// \brief The column nodes this rank owns.
struct ColumnSet {
  std::vector<lid_t> node;     ///< owned local node
  std::vector<lid_t> foot;     ///< its foot's index in the feet list
  std::vector<double> weight;  ///< 1 - (arc length from the foot) / (the column's length)
  lid_t count = 0;             ///< columns on all ranks
  lid_t acrossRanks = 0;       ///< of those, the ones whose nodes more than one rank owns
};

/// \brief The columns above `feet` (global node ids, the same list on every rank). A foot with one
/// edge leaving the feet's surface starts one line; a foot with two, pointing away from each other
/// (a baffle), starts one on each side; any other foot none. From each node a line follows the edge
/// best aligned with its last one, within 60 degrees and with every other edge at least 30 degrees
/// further off, until it reaches a prescribed node. It is dropped when it finds no such edge, meets
/// a sliding node or another foot, or shares a node with a kept line of an earlier foot.
/// Collective over `graph.comm`.
ColumnSet findColumns(const ColumnGraph& graph, const std::vector<gid_t>& feet);

}  // namespace mfsi::coupling
