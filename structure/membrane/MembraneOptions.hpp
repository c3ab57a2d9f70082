#pragma once
/// \file
/// \brief Plain option structs of the membrane solver (filled by a configuration layer; no YAML
/// here): material and wrinkling, static solvers, dynamics, loads, boundary conditions and
/// reinforcements.
#include "core/RigidPlacement.hpp"
#include "structure/membrane/MembraneMaterial.hpp"

#include <array>
#include <functional>
#include <vector>

namespace mfsi {

/// Static (or per-time-step) nonlinear solver.
enum class MembraneStaticSolver {
  /// Newton-Raphson with a lumped (diagonal) stiffness and a displacement limiter: cheap
  /// iterations, no linear solve, many iterations (the seed method).
  LumpedNewtonRaphson,
  /// Newton with the consistent tangent in CSR, Jacobi-preconditioned CG and a backtracking
  /// line search.
  Newton,
};

/// Direction of the pressure load.
enum class MembranePressureDirection {
  Follower,  ///< along the current normal, on the current area (gas pressure)
  Dead,      ///< along the reference normal, on the reference area (fixed load)
};

/// How the pressure of an element is distributed to its nodes.
enum class MembranePressureIntegration {
  Consistent,  ///< Gauss integration of N_a p n dA
  Lumped,      ///< total element pressure force shared equally by its nodes
};

/// Follower-pressure contribution to the Newton matrix.
enum class MembranePressureStiffness {
  None,
  /// Symmetric part of each element's load stiffness. The skew part of the assembled load
  /// stiffness is a sum of terms on free boundary edges only (interior edges cancel by
  /// integration by parts), so for a membrane whose loaded boundary is clamped, or a closed
  /// surface, the symmetrised matrix is the exact tangent; elsewhere it is the best symmetric
  /// approximation, which keeps CG applicable.
  Symmetrized,
};

enum class MembraneMassType { Consistent, Lumped };

enum class MembraneTimeIntegrator {
  Newmark,           ///< beta, gamma (default average acceleration 1/4, 1/2: no numerical damping)
  GeneralizedAlpha,  ///< Chung-Hulbert with spectral radius rhoInfinity (alpha_m, alpha_f, beta, gamma derived)
};

const char* toString(MembraneStaticSolver v);
const char* toString(MembranePressureDirection v);
const char* toString(MembraneTimeIntegrator v);

/// \brief Lumped Newton-Raphson: du = R / K_lumped per dof, with K_lumped the absolute row sum of
/// the tangent (material + geometric). The row sum bounds the largest eigenvalue (Gershgorin), so
/// an undamped step never overshoots in a stiff direction; soft directions (a flat, unstressed
/// membrane has none out of plane) are held by the limiter.
struct MembraneLumpedOptions {
  int maxIterations = 200000;
  /// Largest nodal displacement change per iteration, as a fraction of the characteristic length.
  real limiterFraction = 0.01;
  /// Lower bound of a dof's lumped stiffness as a fraction of the largest one of its node, so an
  /// unstressed out-of-plane direction gets a finite (limited) step.
  real stiffnessFloor = 1e-6;
};

/// \brief Consistent-tangent Newton.
struct MembraneNewtonOptions {
  int maxIterations = 100;
  /// Largest nodal displacement change per iteration (fraction of the characteristic length);
  /// the whole Newton step is scaled down uniformly, keeping its direction.
  real limiterFraction = 0.1;
  /// Residual evaluations allowed per line search (see MembraneSolver.cpp: root of du . R).
  int maxLineSearchSteps = 12;
  MembranePressureStiffness pressureStiffness = MembranePressureStiffness::Symmetrized;
  /// Tangent-only floor of the smallest principal membrane force in the geometric stiffness, as a
  /// fraction of E h. A flat unstressed membrane has no out-of-plane stiffness; the floor gives
  /// the first Newton matrix one without changing the residual (so nor the converged answer).
  /// Compressed directions are lifted to the floor too, and compressed bars/springs lose their
  /// negative geometric term: the matrix stays positive definite (CG applies) where the exact
  /// tangent of a compressed, unwrinkled sheet is indefinite. 0 = the exact tangent.
  real tangentStressFloor = 1e-6;
  /// CG relative tolerance; 0 = adaptive (inexact Newton forcing eta = min(1e-2, max(r, tol/(2r)))
  /// with r the relative nonlinear residual: superlinear, no over-solving far from the answer).
  real cgRelTol = 0;
  int cgMaxIterations = 20000;
};

/// \brief Implicit dynamics.
struct MembraneDynamicsOptions {
  MembraneTimeIntegrator integrator = MembraneTimeIntegrator::Newmark;
  real beta = 0.25;
  real gamma = 0.5;
  real rhoInfinity = 1.0;  ///< generalized-alpha: high-frequency spectral radius in [0, 1]
  MembraneMassType mass = MembraneMassType::Consistent;
  /// Rayleigh damping C = alpha M + beta K, K the tangent at the start of the step.
  real rayleighAlpha = 0;
  real rayleighBeta = 0;
};

/// \brief All options of one membrane.
struct MembraneOptions {
  MembraneMaterial material;
  MembraneWrinklingModel wrinkling = MembraneWrinklingModel::None;
  /// Safeguard stiffness fraction eta of the tension-field tangent (MembraneWrinkling.hpp).
  real wrinklingStiffnessFraction = 1e-3;
  /// Fraction of the elastic law a wrinkled or slack point keeps, in the stress as well
  /// (MembraneLaw::residual): 0 = the pure tension field.
  real wrinklingResidualStiffness = 0;
  MembraneStaticSolver solver = MembraneStaticSolver::Newton;
  /// Convergence: ||R_free|| <= tolerance * max(||F_ext||, ||reactions||, ||R_free at the start||)
  /// (time steps: also ||inertia force||).
  real tolerance = 1e-4;
  /// Static solves ramp the loads and prescribed displacements in this many equal increments.
  int loadSteps = 1;
  /// Length of the displacement limiters; 0 = sqrt(reference area).
  real characteristicLength = 0;
  MembraneLumpedOptions lumped;
  MembraneNewtonOptions newton;
  MembraneDynamicsOptions dynamics;
};

/// \brief Pressure loads. Positive pressure pushes along the element normal (right-hand rule of
/// the element node order). The nodal pressure is
///   p_n = pressure * pressureTime(t) + nodePressure[n] + s_n pressureOffset min(1, t / rampTime),
/// with s_n = +1 where the node's reference normal points away from insidePoint, else -1 (an
/// offset that always inflates), and the pressure at a Gauss point is the interpolated p_n plus
/// elementPressure[e].
struct MembraneLoads {
  MembranePressureDirection direction = MembranePressureDirection::Follower;
  MembranePressureIntegration integration = MembranePressureIntegration::Consistent;
  real pressure = 0;                      ///< uniform pressure (Pa)
  std::function<real(real)> pressureTime;  ///< multiplies `pressure`; empty = 1
  RealView nodePressure;     ///< optional per-node field (Pa), size nNodes (e.g. from the fluid)
  RealView elementPressure;  ///< optional per-element field (Pa), size nElements
  real pressureOffset = 0;   ///< pOffset (Pa)
  std::array<real, 3> insidePoint{0, 0, 0};
  real pressureOffsetRampTime = 0;  ///< 0 = applied at once
  Real3View nodeForce;  ///< optional external nodal forces (N), size nNodes
};

/// \brief Clamped nodes. Without a frame the displacement is zero (or `offsets`); with a frame
/// the node goes to frame(t).apply(X + offset): clamped to a moving parent.
struct MembraneClamp {
  std::vector<lid_t> nodes;
  std::vector<std::array<real, 3>> offsets;  ///< optional per-node displacement before the frame
  std::function<RigidPlacement(real)> frame;  ///< optional, time -> placement
};

/// \brief A linear spring from a node to a fixed anchor point: force k (L - L0) along the line
/// (L0 = 0: the isotropic spring -k (x - anchor)). restLength < 0: the reference distance.
struct MembraneNodeSpring {
  lid_t node = -1;
  std::array<real, 3> anchor{0, 0, 0};
  real stiffness = 0;  ///< k (N/m)
  real restLength = -1;
};

/// \brief Axial bar (edge cable/beam in tension) between two nodes, Total Lagrangian: force
/// EA E_GL with E_GL = (L^2 - L0^2) / (2 L0^2).
struct MembraneEdgeBeam {
  lid_t node0 = -1, node1 = -1;
  real axialStiffness = 0;  ///< EA (N)
  bool tensionOnly = false;  ///< cable: no compression
};

/// \brief Boundary conditions and edge reinforcements.
struct MembraneBoundary {
  std::vector<MembraneClamp> clamps;
  std::vector<lid_t> normalNodes;  ///< constrainToNormal: these move only along their reference normal
  /// Nonzero: every node that is neither clamped nor normal-constrained moves perpendicular to this
  /// direction only (normalised on use). A membrane of a one-cell-thick 2D fluid scene gives the
  /// thickness axis, so its nodes stay in their planes.
  std::array<real, 3> motionPlaneNormal{0, 0, 0};
  std::vector<MembraneNodeSpring> edgeSprings;
  std::vector<MembraneNodeSpring> cornerSprings;
  std::vector<MembraneEdgeBeam> edgeBeams;
};

/// \brief Bars between consecutive nodes of a chain (closed: also last -> first).
std::vector<MembraneEdgeBeam> makeEdgeBeams(const std::vector<lid_t>& chain, real axialStiffness, bool closed,
                                            bool tensionOnly = false);

}  // namespace mfsi
