#include "kernels/Preconditioner.hpp"

#include "core/Error.hpp"

namespace mfsi {

void invertDiagonal(const ExecSpace& exec, const CsrMatrix& A, const RealView& inv) {
  const ConstIndexView diagIdx = A.diagIdx;
  const ConstRealView val = A.values;
  // First bad row (min is order-independent: deterministic); nRows when all are fine.
  lid_t bad = A.nRows;
  Kokkos::parallel_reduce(
      "mfsi::kernels::precond::invertDiagonal", RangePolicy(exec, 0, A.nRows),
      KOKKOS_LAMBDA(lid_t i, lid_t & firstBad) {
        const lid_t k = diagIdx(i);
        const double d = k >= 0 ? val(k) : 0.0;
        const double v = 1.0 / d;
        const bool ok = k >= 0 && d != 0.0 && v - v == 0.0;  // v - v != 0 for inf and NaN
        inv(i) = ok ? v : 0.0;
        if (!ok && i < firstBad) firstBad = i;
      },
      Kokkos::Min<lid_t>(bad));
  MFSI_CHECK(bad >= A.nRows, "linear solver: diagonal entry of row " << bad << " is missing, zero or not finite");
}

void IdentityPreconditioner::setup(const ExecSpace&, const CsrMatrix& A) { n_ = A.nRows; }

void IdentityPreconditioner::apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) {
  Kokkos::parallel_for(
      "mfsi::kernels::precond::identity", RangePolicy(exec, 0, n_), KOKKOS_LAMBDA(lid_t i) { z(i) = r(i); });
}

void JacobiPreconditioner::setup(const ExecSpace& exec, const CsrMatrix& A) {
  invDiag_ =
      RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::kernels::precond::jacobi::invDiag"), A.nRows);
  invertDiagonal(exec, A, invDiag_);
}

void JacobiPreconditioner::updateValues(const ExecSpace& exec, const CsrMatrix& A) {
  if (invDiag_.extent(0) != static_cast<std::size_t>(A.nRows)) return setup(exec, A);
  invertDiagonal(exec, A, invDiag_);
}

void JacobiPreconditioner::apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) {
  const ConstRealView inv = invDiag_;
  Kokkos::parallel_for(
      "mfsi::kernels::precond::jacobi", RangePolicy(exec, 0, static_cast<lid_t>(inv.extent(0))),
      KOKKOS_LAMBDA(lid_t i) { z(i) = inv(i) * r(i); });
}

}  // namespace mfsi
