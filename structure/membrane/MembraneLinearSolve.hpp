#pragma once
/// \file
/// \brief Nodal constraints of the membrane (fixed, or moving along a unit direction only) as a
/// per-node projector P, and the Jacobi-preconditioned conjugate gradient on the projected
/// system P K P du = P R used by the Newton solver.
///
/// Why a projector instead of eliminating rows: constrainToNormal couples the three dofs of a
/// node (du = s n), which row elimination cannot express; with P the CSR matrix stays the
/// assembled one (no copy, no value surgery), and every iterate stays in range(P). The
/// preconditioner is P D^-1 P, D = diag(K): symmetric positive definite on range(P).
#include "kernels/Blas.hpp"

namespace mfsi {

/// Per-node constraint kinds.
/// Free; Fixed; Direction: moves along `direction` only; Plane: moves perpendicular to `direction`
/// only (e.g. the nodes of a one-cell-thick 2D scene, which stay in their z-plane).
enum class MembraneNodeConstraint : int { Free = 0, Fixed = 1, Direction = 2, Plane = 3 };

/// \brief Constraint projector: kind per node and the unit direction of Direction nodes.
struct MembraneConstraints {
  Kokkos::View<int*, MemSpace> kind;
  Real3View direction;
};

namespace membrane {
/// \brief v <- P v for one node.
KOKKOS_INLINE_FUNCTION void projectNode(int kind, real n0, real n1, real n2, real v[3]) {
  if (kind == static_cast<int>(MembraneNodeConstraint::Fixed)) {
    v[0] = v[1] = v[2] = 0;
  } else if (kind == static_cast<int>(MembraneNodeConstraint::Direction)) {
    const real s = v[0] * n0 + v[1] * n1 + v[2] * n2;
    v[0] = s * n0;
    v[1] = s * n1;
    v[2] = s * n2;
  } else if (kind == static_cast<int>(MembraneNodeConstraint::Plane)) {
    const real s = v[0] * n0 + v[1] * n1 + v[2] * n2;
    v[0] -= s * n0;
    v[1] -= s * n1;
    v[2] -= s * n2;
  }
}
}  // namespace membrane

/// \brief out = P in (flat 3 per node; may alias).
void projectConstraints(const ExecSpace& exec, const MembraneConstraints& c, const ConstRealView& in,
                        const RealView& out);

/// \brief Outcome of a projected CG solve.
struct MembraneCgResult {
  int iterations = 0;
  real relativeResidual = 0;  ///< ||P(b - K x)|| / ||P b|| (recursive residual)
  bool converged = false;
  bool negativeCurvature = false;  ///< p.Kp <= 0 met: the projected matrix is not positive definite
};

/// \brief Jacobi-preconditioned CG for P K P x = P b with x in range(P); x starts at zero.
/// Work vectors are kept between calls.
class MembraneCg {
 public:
  MembraneCgResult solve(const ExecSpace& exec, const CsrMatrix& K, const MembraneConstraints& c,
                         const ConstRealView& b, const RealView& x, real relTol, int maxIterations);

 private:
  RealView r_, z_, p_, q_, invDiag_;
  SolverComm comm_;
};

}  // namespace mfsi
