#include "fluid/LinearSolve.hpp"

#include "kernels/Amg.hpp"

#include <cmath>

namespace mfsi::fluid {

LinearSolver::LinearSolver() = default;
LinearSolver::~LinearSolver() = default;
LinearSolver::LinearSolver(LinearSolver&&) noexcept = default;
LinearSolver& LinearSolver::operator=(LinearSolver&&) noexcept = default;

LinearSolver::LinearSolver(lid_t n, PressurePreconditioner pp)
    : uPrec_(std::make_unique<JacobiPreconditioner>()),
      uSolver_(makeKrylovSolver(KrylovMethod::BiCGStab)),
      pSolver_(makeKrylovSolver(KrylovMethod::CG)),
      r_("mfsi::fluid::linear::residual", n) {
  if (pp == PressurePreconditioner::Amg)
    pPrec_ = std::make_unique<AmgPreconditioner>();
  else
    pPrec_ = std::make_unique<JacobiPreconditioner>();
}

void LinearSolver::momentumMatrixChanged(const ExecSpace& exec, const CsrMatrix& A) {
  if (uReady_)
    uPrec_->updateValues(exec, A);
  else
    uPrec_->setup(exec, A);
  uReady_ = true;
}

void LinearSolver::pressureMatrixChanged(const ExecSpace& exec, const CsrMatrix& A) {
  if (pReady_)
    pPrec_->updateValues(exec, A);
  else
    pPrec_->setup(exec, A);
  pReady_ = true;
}

LinearSolveStats LinearSolver::solveMomentum(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                             const RealView& x, const LinearSolverOptions& o) {
  return solve(exec, *uSolver_, *uPrec_, A, b, x, o);
}

LinearSolveStats LinearSolver::solvePressure(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                             const RealView& x, const LinearSolverOptions& o) {
  return solve(exec, *pSolver_, *pPrec_, A, b, x, o);
}

LinearSolveStats LinearSolver::solve(const ExecSpace& exec, KrylovSolver& solver, Preconditioner& M,
                                     const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                                     const LinearSolverOptions& o) {
  LinearSolveStats st;
  const lid_t n = A.nRows;
  // Scaled initial residual (and a round-off scale) in two passes: mean of x, then residual sums.
  real xsum = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::linear::mean", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i, real & acc) { acc += x(i); }, xsum);
  const real xbar = n > 0 ? xsum / n : 0.0;
  ConstIndexView rp = A.rowPtr, ci = A.colIdx;
  ConstRealView v = A.values;
  RealView r = r_;
  real r1 = 0, nf = 0, scale = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::linear::scaledResidual", RangePolicy(exec, 0, n),
      KOKKOS_LAMBDA(lid_t i, real & a, real & f, real & s) {
        real ax = 0, rs = 0;
        for (lid_t k = rp(i); k < rp(i + 1); ++k) {
          ax += v(k) * x(ci(k));
          rs += v(k);
        }
        r(i) = b(i) - ax;
        a += kmath::fabs(r(i));
        f += kmath::fabs(ax - rs * xbar) + kmath::fabs(b(i) - rs * xbar);
        s += kmath::fabs(b(i)) + kmath::fabs(ax);
      },
      r1, nf, scale);
  if (!std::isfinite(r1) || !std::isfinite(nf)) {
    st.breakdown = true;
    st.initialResidual = st.finalResidual = r1;
    return st;
  }
  nf += 1e-300;
  st.initialResidual = st.finalResidual = r1 / nf;
  // Converged already, or the residual is round-off of the terms it is made of (e.g. an exactly
  // preserved uniform flow): iterating would only stir round-off.
  const real roundoff = 1e-14 * scale;
  if (st.initialResidual <= o.tolerance || r1 <= roundoff) {
    st.converged = true;
    return st;
  }
  KrylovOptions ko;
  ko.relTol = o.relTol;
  ko.absTol = std::max(o.tolerance * nf, roundoff) / std::sqrt(static_cast<real>(n));
  ko.maxIterations = o.maxIter;
  solver.setOptions(ko);
  const KrylovResult kr = solver.solve(exec, A, b, x, M);
  st.iterations = kr.iterations;
  st.converged = kr.converged;
  st.breakdown = kr.status == KrylovStatus::NotFinite || kr.status == KrylovStatus::Breakdown;
  st.finalResidual = kr.initialResidual > 0 ? st.initialResidual * kr.finalResidual / kr.initialResidual : 0.0;
  return st;
}

}  // namespace mfsi::fluid
