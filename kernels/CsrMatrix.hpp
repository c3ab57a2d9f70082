#pragma once
/// \file
/// \brief Sparse matrix in compressed-row storage on the device. The sparsity (rowPtr, colIdx) is
/// built once per mesh topology; `values` are refilled every assembly.
#include "core/Types.hpp"

namespace mfsi {

/// \brief Rows per block of the deterministic reductions (blas::reduce) and of the row runs below.
inline constexpr lid_t kRowBlock = 256;

/// \brief Runs of consecutive rows with the same columns relative to the row (col - row), as in the
/// interior of a structured block: every row of a run has the same length and column offsets.
/// Host backends sweep a run with its offsets as loop invariants, so the loads of x are contiguous
/// at i + offset and no column index is read (blas kernels; device backends use the rows). Runs
/// never cross a multiple of kRowBlock, so a reduction block is a whole number of runs.
/// Built with the sparsity (`count` = 0 where runs would be short: unstructured meshes).
struct CsrRowRuns {
  lid_t count = 0;         ///< number of runs; 0: none
  IndexView start;         ///< size count + 1: run r holds rows [start(r), start(r + 1))
  IndexView offsetsAt;     ///< size count: where run r's column offsets begin in `offsets`
  IndexView offsets;       ///< column offsets of the distinct patterns, one after the other
  IndexView blockStart;    ///< size nBlocks + 1: first run of each block of kRowBlock rows
};

/// \brief A rank's rows parted by whether they read a ghost column (>= nRows): interior rows can
/// be multiplied while the ghosts' values are still under way (core/parallel/Halo::begin), the
/// boundary rows after they have arrived. Three partitions of the same rows: single rows (the row
/// kernels), row runs (host sweeps, CsrRowRuns) and reduction blocks of kRowBlock rows (products
/// fused with a sum, whose block partials are then added in block order as without the split). A
/// run or block is a boundary one when any of its rows is. Empty (no lists) on one rank.
struct CsrGhostSplit {
  static constexpr int kInterior = 0, kBoundary = 1;
  IndexView rows[2];
  IndexView runs[2];    ///< run indices; empty without runs
  IndexView blocks[2];  ///< block indices: block b holds rows [b kRowBlock, (b + 1) kRowBlock)
  bool empty() const { return rows[kInterior].extent(0) + rows[kBoundary].extent(0) == 0; }
};

/// \brief CSR matrix. Column indices of a row are sorted; the diagonal entry of row i sits at
/// `diagIdx(i)` for fast access by assembly kernels and Jacobi smoothers.
struct CsrMatrix {
  lid_t nRows = 0;
  lid_t nCols = 0;
  IndexView rowPtr;  ///< size nRows + 1
  IndexView colIdx;  ///< size nnz
  IndexView diagIdx; ///< size nRows: position of the diagonal in colIdx (-1 if absent)
  RealView values;   ///< size nnz
  CsrRowRuns runs;   ///< optional (see CsrRowRuns); follows the sparsity
  CsrGhostSplit ghostSplit;  ///< optional (see CsrGhostSplit); follows the sparsity

  lid_t nnz() const { return static_cast<lid_t>(colIdx.extent(0)); }
};

}  // namespace mfsi
