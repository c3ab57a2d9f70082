#pragma once
/// \file
/// \brief Build the sparsity of a `CsrMatrix` once per topology: from a host adjacency list, or
/// from a hex mesh's cell-face connectivity (finite-volume matrices, one row per cell), with a
/// face -> coefficient-position map so that assembly fills values per face without searching.
#include "core/HexMesh.hpp"
#include "kernels/CsrMatrix.hpp"

#include <array>
#include <string>
#include <vector>

namespace mfsi {

/// \brief Options of the adjacency-based builders.
struct CsrBuildOptions {
  /// Add the diagonal (i, i) to every row even where the adjacency does not list it.
  bool addDiagonal = true;
  /// Number of columns; -1 = the number of rows (square). Larger for ghost columns.
  lid_t nCols = -1;
  /// Expand every node to a blockSize x blockSize dense block (e.g. 3 for displacement dofs):
  /// row r*bs+a couples with columns c*bs+b for every neighbour c (and r itself).
  int blockSize = 1;
  /// Prefix of the View labels (`<label>::rowPtr`, ...).
  std::string label = "mfsi::kernels::csr";
};

/// \brief Sparsity (values zeroed) from a host adjacency list: row i couples with
/// `adjacency[i]` (any order, repeats allowed). Throws InputError for out-of-range columns.
CsrMatrix buildCsr(const std::vector<std::vector<lid_t>>& adjacency, const CsrBuildOptions& options = {});

/// \brief Same from an adjacency in CSR form: row i couples with
/// `neighbours[offsets[i] .. offsets[i+1])` (e.g. a copy of `HexMesh::nodeNodeOffsets/nodeNodes`).
CsrMatrix buildCsr(const std::vector<lid_t>& offsets, const std::vector<lid_t>& neighbours,
                   const CsrBuildOptions& options = {});

/// \brief Where the two off-diagonal coefficients of an internal face sit in `CsrMatrix::values`.
/// For internal face f with owner P and neighbour N: `ownerRow(f)` is the position of a_PN (row P,
/// column N) and `neighbourRow(f)` that of a_NP (row N, column P). A side whose cell is a ghost
/// (not a row of this rank) holds -1. Size: `nInternalFaces()`.
struct FaceCoefficientMap {
  IndexView ownerRow;
  IndexView neighbourRow;
};

/// \brief A cell-centred finite-volume matrix sparsity and its face map.
struct CellCsr {
  CsrMatrix matrix;  ///< rows: owned cells; columns: all cells (owned, then ghosts); values zeroed
  FaceCoefficientMap faceMap;
};

/// \brief One row per owned cell with the diagonal and one column per neighbour across an
/// internal face (a cell pair sharing several faces gets one entry; both faces map to it).
CellCsr buildCellCsr(const HexMesh& mesh, const std::string& label = "mfsi::kernels::cellCsr");

/// \brief Row runs (CsrRowRuns) of a sparsity given on the host (sorted columns per row; columns
/// relative to the row, so ghost columns may follow);
/// empty where the average run would be short. `buildCsr` and `buildCellCsr` attach them already.
CsrRowRuns buildRowRuns(lid_t nRows, const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx,
                        const std::string& label);

/// \brief The ghost split (CsrGhostSplit) of a sparsity of nRows rows whose columns from
/// `firstGhost` on are ghosts (nRows for a rank's square block); empty when no row reads a ghost.
CsrGhostSplit buildGhostSplit(lid_t nRows, lid_t firstGhost, const IndexView& rowPtr, const IndexView& colIdx,
                              const CsrRowRuns& runs, const std::string& label);

/// \brief Boundary condition of the model Poisson matrix.
enum class ModelBoundary {
  Dirichlet,  ///< u = 0 on every side (matrix SPD)
  Neumann,    ///< zero flux on every side (matrix singular: constants are its null space)
};

/// \brief Model problem for solver tests and benchmarks: the cell-centred finite-volume 7-point
/// Laplacian -h^2 Lap on an n[0] x n[1] x n[2] box of cubes, cells numbered x fastest. Each
/// internal face couples its cells with -1 (and adds 1 to both diagonals); a Dirichlet boundary
/// face adds 2 to the diagonal (the wall value sits half a cell away), a Neumann face nothing.
CsrMatrix buildPoisson7(std::array<lid_t, 3> n, ModelBoundary boundary,
                        const std::string& label = "mfsi::kernels::poisson7");

/// \brief Position of column `col` in row `row` of the host arrays, or -1 (binary search on the
/// sorted columns). For set-up code and tests; kernels use the face map or `diagIdx`.
lid_t findEntry(const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx, lid_t row, lid_t col);

}  // namespace mfsi
