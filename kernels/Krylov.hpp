#pragma once
/// \file
/// \brief Preconditioned Krylov solvers: conjugate gradients (symmetric systems: pressure,
/// membrane stiffness) and BiCGStab (non-symmetric: momentum with convection).
///
/// Failure to converge is reported in `KrylovResult`, never thrown: the caller decides (the
/// time loop may cut the step). A NaN/inf residual stops the solve with `status = NotFinite`.
#include "kernels/Preconditioner.hpp"

#include <memory>
#include <string>

namespace mfsi {

enum class KrylovMethod { CG, BiCGStab };

/// \brief What the relative tolerance is relative to.
enum class ResidualReference {
  InitialResidual,  ///< ||b - A x0||
  RightHandSide,    ///< ||b|| (better with a good initial guess, e.g. the previous time step)
};

/// \brief Null space of a singular system that the solver projects out.
enum class NullSpace {
  None,
  /// Constant vectors (pure-Neumann pressure Poisson: rows sum to zero). The residual and every
  /// preconditioned residual are projected onto zero mean, so the solver converges on the
  /// consistent part of b (b minus its mean; exact when b is consistent), and the returned x has
  /// zero mean.
  Constant,
};

/// \brief Stopping rule: ||r|| <= max(absTol, relTol * ||reference||) (2-norms), or maxIterations.
struct KrylovOptions {
  real relTol = 1e-8;
  real absTol = 0.0;
  int maxIterations = 1000;
  ResidualReference relativeTo = ResidualReference::InitialResidual;
  NullSpace nullSpace = NullSpace::None;
};

enum class KrylovStatus {
  Converged,
  MaxIterations,  ///< tolerance not reached within maxIterations
  Breakdown,      ///< a zero denominator (e.g. p.Ap = 0, or BiCGStab rho = 0) before convergence
  NotFinite,      ///< NaN or inf in the residual or a scalar of the recurrence
};

const char* toString(KrylovStatus status);

/// \brief Outcome of a solve. Residuals are 2-norms of the recursively updated residual (after
/// projection, for a singular system); the initial one is computed explicitly from b - A x0.
struct KrylovResult {
  int iterations = 0;
  real initialResidual = 0.0;
  real finalResidual = 0.0;
  bool converged = false;
  KrylovStatus status = KrylovStatus::MaxIterations;
};

/// \brief Common interface of the Krylov methods; work vectors are kept between solves (and
/// reallocated when the matrix size changes).
class KrylovSolver {
 public:
  explicit KrylovSolver(const KrylovOptions& options = {}, const SolverComm& comm = {})
      : options_(options), comm_(comm) {}
  virtual ~KrylovSolver() = default;

  /// \brief Solve A x = b starting from x (an initial guess: zero it for none). `M` must have been
  /// set up for A. b has nRows entries, x at least nCols.
  virtual KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                             Preconditioner& M) = 0;

  const KrylovOptions& options() const { return options_; }
  void setOptions(const KrylovOptions& options) { options_ = options; }

 protected:
  KrylovOptions options_;
  SolverComm comm_;
};

/// \brief Preconditioned conjugate gradients. A and M must be symmetric and definite (both
/// positive, or both negative).
class ConjugateGradient final : public KrylovSolver {
 public:
  using KrylovSolver::KrylovSolver;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M) override;

 private:
  RealView r_, z_, p_, q_;
};

/// \brief Right-preconditioned BiCGStab (van der Vorst 1992) for non-symmetric systems.
class BiCGStab final : public KrylovSolver {
 public:
  using KrylovSolver::KrylovSolver;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M) override;

 private:
  RealView r_, rhat_, p_, v_, phat_, shat_, t_;
};

/// \brief The solver for a method (configuration layers choose by enum).
std::unique_ptr<KrylovSolver> makeKrylovSolver(KrylovMethod method, const KrylovOptions& options = {},
                                               const SolverComm& comm = {});

}  // namespace mfsi
