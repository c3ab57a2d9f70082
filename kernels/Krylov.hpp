#pragma once
/// \file
/// \brief Preconditioned Krylov solvers: conjugate gradients (symmetric systems: pressure,
/// membrane stiffness) and BiCGStab (non-symmetric: momentum with convection).
///
/// Failure to converge is reported in `KrylovResult`, never thrown: the caller decides (the
/// time loop may cut the step). A NaN/inf residual stops the solve with `status = NotFinite`.
#include "kernels/LatticeMatrix.hpp"
#include "kernels/Preconditioner.hpp"

#include <array>
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

/// \brief Stopping rule: converged when ||r||_2 <= max(absTol, relTol * ||reference||_2), or when
/// ||r||_1 <= l1AbsTol; otherwise stop after maxIterations. r is the solver's recursively updated
/// residual, tested after every update of x (BiCGStab: also at its half step).
struct KrylovOptions {
  real relTol = 1e-8;
  real absTol = 0.0;
  /// Absolute tolerance on the 1-norm sum_i |r_i| (global). OpenFOAM's solvers stop on a scaled
  /// 1-norm; a caller that knows the scale passes tolerance * scale here and stops exactly where
  /// OpenFOAM would, instead of on a 2-norm bound that implies it (|r|_1 <= sqrt(n) |r|_2, which
  /// over-solves). The 1-norm is summed in a reduction the solver does anyway. 0 (default): only
  /// an exactly zero residual satisfies it, i.e. the 2-norm rule alone decides.
  real l1AbsTol = 0.0;
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

/// \brief Outcome of a solve. Residuals are norms of the recursively updated residual (after
/// projection, for a singular system); the initial one is b - A x0, computed explicitly (or given).
struct KrylovResult {
  int iterations = 0;
  real initialResidual = 0.0;    ///< ||r0||_2
  real finalResidual = 0.0;      ///< ||r||_2 at the end
  real initialResidualL1 = 0.0;  ///< ||r0||_1
  real finalResidualL1 = 0.0;    ///< ||r||_1 at the end
  bool converged = false;
  KrylovStatus status = KrylovStatus::MaxIterations;
};

/// \brief An initial residual r0 = b - A x0 the caller has already formed (e.g. in a pass that also
/// computes a scaled residual), with its global norms, so the solver skips its own residual pass.
/// The solver works in `r` (it is overwritten with the final residual). With NullSpace::Constant
/// the solver projects it (and recomputes the norms) itself.
struct InitialResidual {
  RealView r;     ///< rows [0, nRows): b - A x0
  real rr = 0.0;  ///< global r.r
  real l1 = 0.0;  ///< global sum |r_i|
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

  /// \brief Same, starting from the residual `r0` = b - A x of the given x (not recomputed).
  virtual KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                             Preconditioner& M, const InitialResidual& r0) = 0;

  /// \brief Announce A's values (new, or refilled in place) before solving with it. Solvers that
  /// keep a copy of the matrix (ConjugateGradient: a symmetric lattice copy) refresh it here;
  /// the default does nothing. A solve with a matrix that was not announced is still correct.
  virtual void matrixChanged(const ExecSpace& exec, const CsrMatrix& A) {
    (void)exec;
    (void)A;
  }

  const KrylovOptions& options() const { return options_; }
  void setOptions(const KrylovOptions& options) { options_ = options; }

 protected:
  KrylovOptions options_;
  SolverComm comm_;
};

/// \brief Preconditioned conjugate gradients. A and M must be symmetric and definite (both
/// positive, or both negative).
///
/// Lattice copy: after `matrixChanged(exec, A)` on a symmetric 7-point (5-point one cell thick)
/// lattice matrix (see SymmetricLatticeMatrix), the product q = A p of every iteration uses a
/// copy of A's diagonal and upper couplings (32 B per row instead of CSR's 56 B), the same
/// products to rounding. A solve uses the copy only for the matrix object it was made from
/// (same rowPtr, colIdx and values views); any other matrix, or one that is not a symmetric
/// lattice, is multiplied in CSR. Values changed in place must be announced again with
/// `matrixChanged` (as AmgPreconditioner::updateValues): a stale copy would be used otherwise.
/// The copy holds shallow references to the announced matrix's views.
class ConjugateGradient final : public KrylovSolver {
 public:
  using KrylovSolver::KrylovSolver;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M) override;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M, const InitialResidual& r0) override;
  /// \brief Refresh the lattice copy from A (one device kernel; the lattice is detected on the
  /// host once per sparsity).
  void matrixChanged(const ExecSpace& exec, const CsrMatrix& A) override;
  /// \brief Whether a solve with A would use the lattice copy.
  bool usesLatticeCopy(const CsrMatrix& A) const { return lattice_.matches(A); }
  /// \brief The lattice copy of A, or nullptr when a solve with A would not use one (callers
  /// with more passes over A, e.g. initial residuals, use it too).
  const SymmetricLatticeMatrix* latticeCopy(const CsrMatrix& A) const {
    return lattice_.matches(A) ? &lattice_ : nullptr;
  }
  /// \brief The lattice itself, for a caller that assembles into it directly (see
  /// SymmetricLatticeMatrix::prepare).
  SymmetricLatticeMatrix& lattice() { return lattice_; }

  /// \brief The iteration behind both `solve` overloads (r0: the given initial residual, or null).
  /// Public only because nvcc compiles extended device lambdas solely in public member functions.
  KrylovResult run(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                   Preconditioner& M, const InitialResidual* r0);

 private:
  RealView r_, z_, p_, q_;
  SymmetricLatticeMatrix lattice_;
};

/// \brief Right-preconditioned BiCGStab (van der Vorst 1992) for non-symmetric systems.
class BiCGStab final : public KrylovSolver {
 public:
  using KrylovSolver::KrylovSolver;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M) override;
  KrylovResult solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                     Preconditioner& M, const InitialResidual& r0) override;

  /// \brief The iteration behind both `solve` overloads (r0: the given initial residual, or null).
  /// Public only because nvcc compiles extended device lambdas solely in public member functions.
  KrylovResult run(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                   Preconditioner& M, const InitialResidual* r0);

 private:
  RealView r_, rhat_, p_, v_, phat_, shat_, t_;
};

/// \brief Initial residuals R0 = B - A X0 of the three columns, formed by the caller (see
/// `InitialResidual`); the solver works in `r` (overwritten).
struct InitialResidual3 {
  Real3View r;               ///< rows [0, nRows); at least nCols rows (the rest is ghost work space)
  std::array<real, 3> rr{};  ///< global r.r per column
  std::array<real, 3> l1{};  ///< global |r|_1 per column
};

/// \brief Right-preconditioned BiCGStab for three right-hand sides of one matrix (the velocity
/// components of the momentum equation), with Jacobi preconditioning.
///
/// Design rationale: the three systems share A and the preconditioner but nothing else, so they
/// are three independent BiCGStab recurrences - each column has its own scalars, stopping test,
/// iteration count and status, and gives the iterates of a separate `BiCGStab` + Jacobi solve of
/// that column (the same recurrence; the products form (a_ij d_j) x_j where the separate solve
/// forms a_ij (d_j x_j), so they agree to round-off, as tested). What is shared is
/// the memory traffic: the columns are advanced in lockstep on n x 3 multi-vectors (the layout of
/// the fluid's U), so each SpMV reads A once for all three, each iteration's reductions of the
/// three columns are one `blas::reduce` (4 global reductions per iteration, not 12), and the
/// Jacobi scaling is applied inside the SpMV gathers and the x update instead of in separate
/// passes (the preconditioned vectors are never stored). A column that has converged (or broken
/// down) is frozen: x and r of that column are no longer touched while the others iterate, and
/// on host backends the products skip its gathers.
/// Jacobi is built in (not a `Preconditioner&`) because fusing it needs the inverse diagonal
/// inside the kernels; a multigrid preconditioner would not fuse anyway.
class BiCGStab3 {
 public:
  explicit BiCGStab3(const KrylovOptions& options = {}, const SolverComm& comm = {});

  /// \brief Solve A x_c = b_c for the three columns c, starting from x (n x 3, at least nCols rows).
  /// `invDiag(i)` = 1 / a_ii (see `invertDiagonal`), at least nCols entries: the kernels read it at
  /// neighbour columns, so ghost entries must hold the owning rank's values. NullSpace::Constant is
  /// not supported.
  std::array<KrylovResult, 3> solve(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                    const Real3View& x, const ConstRealView& invDiag);

  /// \brief Same, starting from the residuals `r0` = B - A X of the given X (not recomputed).
  std::array<KrylovResult, 3> solve(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                    const Real3View& x, const ConstRealView& invDiag, const InitialResidual3& r0);

  const std::array<KrylovOptions, 3>& options() const { return options_; }
  /// \brief The same options for the three columns.
  void setOptions(const KrylovOptions& options) { options_ = {options, options, options}; }
  /// \brief Per-column options (e.g. a 1-norm tolerance scaled per velocity component).
  void setOptions(const std::array<KrylovOptions, 3>& options) { options_ = options; }

  /// \brief The iteration behind both `solve` overloads (r0: the given initial residual, or null).
  /// Public only because nvcc compiles extended device lambdas solely in public member functions.
  std::array<KrylovResult, 3> run(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                  const Real3View& x, const ConstRealView& invDiag, const InitialResidual3* r0);

 private:
  std::array<KrylovOptions, 3> options_;
  SolverComm comm_;
  Real3View r_, rhat_, p_, v_, t_;
};

/// \brief The solver for a method (configuration layers choose by enum).
std::unique_ptr<KrylovSolver> makeKrylovSolver(KrylovMethod method, const KrylovOptions& options = {},
                                               const SolverComm& comm = {});

}  // namespace mfsi
