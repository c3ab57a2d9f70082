#pragma once
/// \file
/// \brief The fluid's single entry point to the shared linear solvers of kernels/: BiCGStab with
/// Jacobi for momentum (one component at a time, or the three velocity components together with
/// `BiCGStab3`), CG with AMG (or Jacobi) for pressure. Keeps the preconditioners between solves
/// (the sparsity is fixed; only values are refreshed).
///
/// Residuals are reported with OpenFOAM's scaling, |b - Ax|_1 / (|Ax - A xbar|_1 + |b - A xbar|_1)
/// with xbar the mean of x, which depends neither on the size nor on the offset of the solution,
/// so one tolerance serves every equation and mesh. The solves stop on that same scaled residual,
/// as OpenFOAM's do: the tolerance times the normalisation factor is the Krylov solver's 1-norm
/// tolerance (`KrylovOptions::l1AbsTol`, summed inside reductions the solver does anyway), and relTol
/// is a fraction of the initial 1-norm. The pass that computes the scaled initial residual also
/// forms r = b - A x and hands it to the Krylov solver as its starting residual (no second pass).
/// All sums are deterministic (`blas::reduce`): solves are bitwise repeatable.
#include "fluid/FluidOptions.hpp"
#include "core/io/Checkpoint.hpp"
#include "kernels/CsrMatrix.hpp"
#include "kernels/Krylov.hpp"

#include <array>
#include <memory>

namespace mfsi::fluid {

/// \brief How `LinearSolver::momentumMatrixChanged` gets the Jacobi inverse diagonal.
enum class InverseDiagonal {
  Compute,  ///< a pass over the matrix diagonal (invertDiagonal)
  Given     ///< the caller wrote 1 / a_ii (0 where zero or not finite) into momentumInverseDiagonal()
};

/// \brief Result of one linear solve (scaled residuals, see the file comment).
struct LinearSolveStats {
  int iterations = 0;
  real initialResidual = 0;
  /// Scaled 1-norm of the solver's final (recursively updated) residual, with the normalisation
  /// factor of the initial x (as OpenFOAM reports it).
  real finalResidual = 0;
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

  /// \brief Solve over ranks: every sum through `comm`, ghost entries of x refreshed through it
  /// before a product; `pressure` replaces the pressure preconditioner (one that works across
  /// ranks). Matrices are then the owned rows of a decomposed mesh (columns: owned, then ghosts).
  void distribute(const SolverComm& comm, std::unique_ptr<Preconditioner> pressure);
  /// \brief The momentum matrix got new values (same sparsity): refresh its preconditioner.
  void momentumMatrixChanged(const ExecSpace& exec, const CsrMatrix& A,
                             InverseDiagonal inverse = InverseDiagonal::Compute);
  /// \brief Storage of the momentum Jacobi's inverse diagonal (n entries), for a caller that
  /// forms it while assembling (then `momentumMatrixChanged(..., InverseDiagonal::Given)`).
  RealView momentumInverseDiagonal(lid_t n);
  /// \brief The pressure matrix got new values (same sparsity): refresh its preconditioner.
  void pressureMatrixChanged(const ExecSpace& exec, const CsrMatrix& A);
  /// \brief The pressure matrix values were (re)assembled: refresh the Krylov solver's own copy
  /// (CG's symmetric lattice copy). Call after every assembly of the values, also between
  /// preconditioner refreshes.
  void pressureValuesChanged(const ExecSpace& exec, const CsrMatrix& A);
  /// \brief CG's lattice for an assembly that writes the pressure matrix's values there instead
  /// of into A's CSR values (see SymmetricLatticeMatrix::prepare), or nullptr when A's sparsity
  /// is not a lattice. After writing: `pressureLatticeAssembled(A)` (instead of
  /// `pressureValuesChanged`). `pressureMatrixChanged` then fills A's CSR values from the lattice
  /// first.
  SymmetricLatticeMatrix* pressureLattice(const CsrMatrix& A);
  void pressureLatticeAssembled(const CsrMatrix& A);
  /// \brief Solve the momentum system A x = b (x holds the initial guess).
  LinearSolveStats solveMomentum(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                                 const LinearSolverOptions& o);
  /// \brief Solve A x_c = b_c for the three velocity components c at once (x: n x 3, e.g. the
  /// velocity field, holds the initial guess and is updated in place). One pass over A forms the
  /// three residuals and scaled residuals; each component stops on its own scaled residual and
  /// gets the iterates `solveMomentum` would give it. Needs `momentumMatrixChanged` first.
  std::array<LinearSolveStats, 3> solveMomentum3(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                                 const Real3View& x, const LinearSolverOptions& o);
  /// \brief Solve the (symmetric positive definite) pressure system A x = b.
  LinearSolveStats solvePressure(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                                 const LinearSolverOptions& o);
  /// \brief The multiple s of d that minimises the energy norm of the error of x + s d for the
  /// symmetric positive definite pressure system A x = b: s = d.(b - A x) / d.A d (one Galerkin
  /// step along d; 0 when d.A d is not positive or a sum is not finite). x and d are not changed.
  /// One pass over A (symmetry gives d.(A x) = (A d).x); on CG's lattice copy when A has one.
  real pressureStepAlong(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const ConstRealView& x,
                         const ConstRealView& d);

  /// \brief Write how the pressure preconditioner came to be (the matrix values of its set-up and
  /// of its last refresh, and the AMG sweeps each saw) for a checkpoint.
  void savePressurePreconditioner(io::StateWriter& w) const;
  /// \brief Rebuild the pressure preconditioner from a checkpoint by replaying its set-up and last
  /// refresh on A's sparsity: the same preconditioner, bit for bit. Overwrites A's values.
  void loadPressurePreconditioner(const io::StateReader& r, const ExecSpace& exec, const CsrMatrix& A);

  /// \brief One Krylov solve with the statistics the solves above report (their shared step).
  /// Public only because nvcc compiles extended device lambdas solely in public member functions.
  LinearSolveStats solve(const ExecSpace& exec, KrylovSolver& solver, Preconditioner& M, const CsrMatrix& A,
                         const ConstRealView& b, const RealView& x, const LinearSolverOptions& o);

 private:

  SolverComm comm_;
  std::unique_ptr<Preconditioner> uPrec_, pPrec_;
  std::unique_ptr<KrylovSolver> uSolver_;
  std::unique_ptr<ConjugateGradient> pSolver_;
  BiCGStab3 u3Solver_;
  RealView uInvDiag_;  ///< Jacobi of the momentum matrix, shared by uPrec_ and u3Solver_
  bool uReady_ = false, pReady_ = false;
  RealView r_;
  Real3View r3_;
  /// What the pressure preconditioner was built from, so that a checkpoint can rebuild it exactly:
  /// the values of its set-up and of its last refresh (copied once per refresh), and the AMG
  /// finest-level sweeps in force at each and now.
  struct PressurePreconditionerHistory {
    RealView setupValues, refreshValues;
    bool refreshed = false;
    int setupSweeps = 0, refreshSweeps = 0, sweeps = 0;
  };
  PressurePreconditionerHistory pHistory_;
};

}  // namespace mfsi::fluid
