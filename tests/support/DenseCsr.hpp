#pragma once
/// \file
/// \brief A CSR matrix as a dense Eigen matrix on the host (small test problems: eigenvalues,
/// comparisons against hand-built matrices).
#include "kernels/CsrMatrix.hpp"

#include <Eigen/Dense>

namespace mfsi::test {

inline Eigen::MatrixXd dense(const CsrMatrix& A) {
  auto rp = Kokkos::create_mirror_view_and_copy(HostSpace(), A.rowPtr);
  auto ci = Kokkos::create_mirror_view_and_copy(HostSpace(), A.colIdx);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), A.values);
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(A.nRows, A.nCols);
  for (lid_t i = 0; i < A.nRows; ++i)
    for (lid_t k = rp(i); k < rp(i + 1); ++k) D(i, ci(k)) += v(k);
  return D;
}

}  // namespace mfsi::test
