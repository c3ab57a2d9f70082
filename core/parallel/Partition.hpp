#pragma once
/// \file
/// \brief Decomposition of a hex mesh's cells over ranks: METIS k-way on the cell dual graph
/// (cells joined by shared faces), with cell weights and groups of cells that must stay on one
/// rank (the cells next to a membrane, so that the membrane's FEM needs no communication: the
/// seed's `singleProcessorFaceSets`).
///
/// Groups are honoured by contracting the graph: each group becomes one vertex whose weight is
/// the sum of its cells' weights and whose edges are the sums of its cells' edges; METIS
/// partitions the contracted graph and the answer is expanded back. The result is deterministic
/// (a fixed METIS seed) and the same on every rank that computes it.
#include "core/HexMesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace mfsi {

/// \brief What to partition for.
struct PartitionOptions {
  int parts = 1;
  /// Per-cell weights (empty: all 1).
  std::vector<std::int32_t> cellWeights;
  /// Groups of cells kept on one rank (groups that share a cell are merged).
  std::vector<std::vector<lid_t>> keepTogether;
  int seed = 7;
};

/// \brief The decomposition and its figures.
struct Partition {
  int parts = 1;
  std::vector<int> cellRank;            ///< rank of each cell
  std::vector<lid_t> cellsPerRank;      ///< owned cells per rank
  std::int64_t edgeCut = 0;             ///< faces between cells of different ranks
  double imbalance = 1;                 ///< max over ranks of (weight / mean weight)
};

/// \brief Cell dual graph in CSR form (neighbours sorted, one entry per shared face).
struct CellGraph {
  std::vector<lid_t> offsets;
  std::vector<lid_t> neighbours;
};

/// \brief The cells of `mesh` joined by their shared faces (baffle faces included: they join the
/// two cells on either side of a membrane).
CellGraph cellDualGraph(const HexMeshInput& mesh);

/// \brief The same for a built mesh: internal faces plus each baffle's face pairs.
CellGraph cellDualGraph(const HexMesh& mesh);

/// \brief METIS k-way decomposition of the cells of `graph` (see the file comment). Throws
/// InputError when `parts` < 1 or exceeds the number of movable units (cells after merging the
/// groups).
Partition partitionGraph(const CellGraph& graph, const PartitionOptions& options);

/// \brief METIS k-way decomposition of `mesh` (see the file comment). Throws InputError when
/// `parts` < 1 or exceeds the number of movable units (cells after merging the groups).
Partition partitionCells(const HexMeshInput& mesh, const PartitionOptions& options);

/// \brief A cell -> rank map as `mfsi partition` writes it: comment lines starting with '#', then
/// one rank per line in the mesh's cell order. Throws InputError naming the file and line for a
/// missing file, a line that is not a rank in [0, ranks), a count other than `nCells`, or a rank
/// left without cells.
std::vector<int> readPartitionMap(const std::string& file, std::size_t nCells, int ranks);

/// \brief Figures of a given cell -> rank map (edge cut, cells per rank, imbalance).
Partition describePartition(const CellGraph& graph, std::vector<int> cellRank, int parts);

}  // namespace mfsi
