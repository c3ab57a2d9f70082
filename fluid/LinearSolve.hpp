#pragma once
/// \file
/// \brief The fluid's single entry point to the shared linear solvers of kernels/: BiCGStab with
/// Jacobi for momentum, CG with AMG (or Jacobi) for pressure. Keeps the preconditioners between
/// solves (the sparsity is fixed; only values are refreshed).
///
/// Residuals are reported with OpenFOAM's scaling, |b - Ax|_1 / (|Ax - A xbar|_1 + |b - A xbar|_1)
/// with xbar the mean of x, which depends neither on the size nor on the offset of the solution,
/// so one tolerance serves every equation and mesh. The Krylov solvers stop on 2-norms; the
/// scaled tolerance is turned into a 2-norm bound that implies it (|r|_1 <= sqrt(n) |r|_2).
#include "fluid/FluidOptions.hpp"
#include "kernels/CsrMatrix.hpp"
#include "kernels/Krylov.hpp"

#include <memory>

namespace mfsi::fluid {

/// \brief Result of one linear solve (scaled residuals, see the file comment).
struct LinearSolveStats {
  int iterations = 0;
  real initialResidual = 0;
  real finalResidual = 0;  ///< initial residual times the 2-norm reduction of the Krylov solve
  bool converged = false;
  bool breakdown = false;  ///< NaN/inf or a Krylov breakdown
};

/// \brief Momentum and pressure solvers with their preconditioners.
class LinearSolver {
 public:
  LinearSolver();
  LinearSolver(lid_t n, PressurePreconditioner pressurePreconditioner);
  ~LinearSolver();
  LinearSolver(LinearSolver&&) noexcept;
  LinearSolver& operator=(LinearSolver&&) noexcept;

  /// \brief The momentum matrix got new values (same sparsity): refresh its preconditioner.
  void momentumMatrixChanged(const ExecSpace& exec, const CsrMatrix& A);
  /// \brief The pressure matrix got new values (same sparsity): refresh its preconditioner.
  void pressureMatrixChanged(const ExecSpace& exec, const CsrMatrix& A);
  /// \brief Solve the momentum system A x = b (x holds the initial guess).
  LinearSolveStats solveMomentum(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                                 const LinearSolverOptions& o);
  /// \brief Solve the (symmetric positive definite) pressure system A x = b.
  LinearSolveStats solvePressure(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                                 const LinearSolverOptions& o);

 private:
  LinearSolveStats solve(const ExecSpace& exec, KrylovSolver& solver, Preconditioner& M, const CsrMatrix& A,
                         const ConstRealView& b, const RealView& x, const LinearSolverOptions& o);

  std::unique_ptr<Preconditioner> uPrec_, pPrec_;
  std::unique_ptr<KrylovSolver> uSolver_, pSolver_;
  bool uReady_ = false, pReady_ = false;
  RealView r_;
};

}  // namespace mfsi::fluid
