#pragma once
/// \file
/// \brief The point-Laplacian of the mesh motion solved, not swept: Jacobi-preconditioned
/// conjugate gradients on the (weighted) graph Laplacian of a SmoothingGraph, with the fixed
/// nodes' values as Dirichlet data.
///
/// Why: Jacobi sweeps spread a boundary displacement by about sqrt(sweeps) cells, so on a mesh
/// of N cells across, a wall deflection of several cell heights is carried by the first few cell
/// rows alone until some N^2 sweeps have run (a 32 x 32 cavity whose bottom bulges by 2.5 cells
/// halves its minimum scaled Jacobian after 50 sweeps). CG reaches the harmonic displacement -
/// what the sweeps converge to - in O(N) iterations of the same stencil. The solve starts from
/// the current values (a warm start), and a zero right-hand side returns at once with the values
/// untouched, bit for bit.
///
/// Preconditioners: the diagonal (Jacobi: one fused kernel per iteration, O(N) iterations), or a
/// smoothed-aggregation AMG V-cycle per component (kernels/Amg.hpp) on the scalar graph Laplacian
/// of the free nodes: a few iterations at any size, each ~ten kernels per component. The graph's
/// weights are those of the reference mesh, so the AMG is set up once, on first use, and kept in
/// the work struct. A sliding node is held, for the AMG, in the component
/// its plane's normal points along, and the preconditioned residual is projected on its plane (the
/// operator's range there), so CG stays in the constrained space.
#include "kernels/Amg.hpp"
#include "kernels/JacobiSmoothing.hpp"

#include <array>
#include <memory>

namespace mfsi {

enum class LaplacianPreconditioner { Jacobi, Amg };

struct LaplacianCgOptions {
  double relTol = 1e-8;     ///< stop when ||r|| <= relTol ||r_0|| (r_0 of the warm start)
  /// Also stop when ||r|| <= relTol ||D d_0|| (d_0 the warm start's free entries, D the diagonal):
  /// a tolerance on the scale of the field, not of the warm start's residual, so that a good warm
  /// start (the previous coupling iteration's motion) ends the solve early instead of reducing
  /// an already small residual by relTol once more.
  bool fieldScaled = false;
  double absTol = 0;        ///< or ||r|| <= absTol, or at round-off: ||r|| <= 1e-13 ||D d|| (D the diagonal)
  int maxIterations = 2000;
  LaplacianPreconditioner preconditioner = LaplacianPreconditioner::Jacobi;
};

struct LaplacianCgResult {
  int iterations = 0;
  double initialResidual = 0;
  double residual = 0;
  bool converged = false;
};

/// \brief Work vectors of `laplacianCg` (allocated on first use, kept between calls).
struct LaplacianCgWork {
  Real3View r, p, q;
  RealView inverseDiagonal;
  // AMG (set up on the first solve that asks for it, for the graph of that solve).
  Real3View z;
  RealView rc, zc;  ///< one component of r and z on its free nodes
  /// Per component: the scalar Laplacian on the nodes free in it (a sliding node is held in the
  /// component its plane's normal points along), the node of every row, the hierarchy; the three
  /// share one when no node slides.
  std::array<IndexView, 3> freeNodes;
  std::array<CsrMatrix, 3> matrix;
  std::array<std::shared_ptr<AmgPreconditioner>, 3> amg;
};

/// \brief Solve sum_j w_ij (d_i - d_j) = 0 for every free node i (the fixed nodes keep their
/// values), all three components at once, starting from d. Deterministic (fixed-order reductions).
LaplacianCgResult laplacianCg(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, LaplacianCgWork& work,
                              const LaplacianCgOptions& options);

}  // namespace mfsi
