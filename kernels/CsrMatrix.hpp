#pragma once
/// \file
/// \brief Sparse matrix in compressed-row storage on the device. The sparsity (rowPtr, colIdx) is
/// built once per mesh topology; `values` are refilled every assembly.
#include "core/Types.hpp"

namespace mfsi {

/// \brief CSR matrix. Column indices of a row are sorted; the diagonal entry of row i sits at
/// `diagIdx(i)` for fast access by assembly kernels and Jacobi smoothers.
struct CsrMatrix {
  lid_t nRows = 0;
  lid_t nCols = 0;
  IndexView rowPtr;  ///< size nRows + 1
  IndexView colIdx;  ///< size nnz
  IndexView diagIdx; ///< size nRows: position of the diagonal in colIdx (-1 if absent)
  RealView values;   ///< size nnz

  lid_t nnz() const { return static_cast<lid_t>(colIdx.extent(0)); }
};

}  // namespace mfsi
