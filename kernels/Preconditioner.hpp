#pragma once
/// \file
/// \brief Preconditioner interface of the Krylov solvers, and the identity and Jacobi
/// preconditioners. The algebraic multigrid preconditioner is in kernels/Amg.hpp.
#include "kernels/Blas.hpp"

#include <string>

namespace mfsi {

/// \brief z = M^{-1} r, an approximate inverse of the system matrix.
///
/// Design rationale: the choice of preconditioner is a run-time option (scene file), and the
/// implementations differ in kind: Jacobi is one kernel, AMG is a host-driven recursion over
/// levels calling many kernels. So dispatch is a virtual call on the *host*, once per apply;
/// the kernels inside each implementation are plain device lambdas with no virtual calls. The
/// set-up is split from the value update because the fluid refills matrix values every step on a
/// fixed sparsity: `updateValues` may reuse everything that depends only on the sparsity (for AMG:
/// aggregates, prolongator and coarse-operator sparsity).
class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  Preconditioner() = default;
  Preconditioner(const Preconditioner&) = delete;
  Preconditioner& operator=(const Preconditioner&) = delete;

  /// \brief Build for matrix A (sparsity and values). A's Views are kept (shallow), so A must stay
  /// alive, and a later `updateValues` sees values refilled in place.
  virtual void setup(const ExecSpace& exec, const CsrMatrix& A) = 0;

  /// \brief A's values changed, its sparsity did not (same rowPtr/colIdx). Default: full set-up.
  virtual void updateValues(const ExecSpace& exec, const CsrMatrix& A) { setup(exec, A); }

  /// \brief z = M^{-1} r on rows [0, nRows) of the matrix given to `setup`. `r` and `z` must not
  /// alias; `z` has at least nCols entries (its ghost entries may be overwritten).
  virtual void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) = 0;

  /// \brief Short name for logs ("jacobi", "amg", ...).
  virtual std::string name() const = 0;
};

/// \brief z = r.
class IdentityPreconditioner final : public Preconditioner {
 public:
  void setup(const ExecSpace& exec, const CsrMatrix& A) override;
  void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) override;
  std::string name() const override { return "none"; }

 private:
  lid_t n_ = 0;
};

/// \brief Diagonal (Jacobi) preconditioner, z_i = r_i / a_ii. Set-up throws InputError when a
/// diagonal entry is missing or zero.
class JacobiPreconditioner final : public Preconditioner {
 public:
  void setup(const ExecSpace& exec, const CsrMatrix& A) override;
  void updateValues(const ExecSpace& exec, const CsrMatrix& A) override;
  void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) override;
  std::string name() const override { return "jacobi"; }

 private:
  RealView invDiag_;
};

/// \brief inv(i) = 1 / a_ii for every row of A. Throws InputError naming the first row whose
/// diagonal is missing, zero or not finite. Shared by Jacobi and the AMG smoothers.
void invertDiagonal(const ExecSpace& exec, const CsrMatrix& A, const RealView& inv);

}  // namespace mfsi
