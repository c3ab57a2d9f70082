#pragma once
/// \file
/// \brief Geometrically nonlinear Total-Lagrangian membrane solver: statics by lumped
/// Newton-Raphson (diagonal stiffness + displacement limiter) or consistent-tangent Newton
/// (CSR + Jacobi-CG + backtracking line search), and implicit dynamics (Newmark or
/// generalized-alpha, consistent or lumped mass, Rayleigh damping).
///
/// Example (Hencky's problem):
/// \code
///   MembraneDiscSpec disc;  disc.radius = 1;  disc.nCore = disc.nRing = 8;
///   MembraneMesh mesh = buildMembraneMesh(generateDiscMesh(disc));
///   MembraneOptions opt;    opt.material = {1e9, 0.3, 1e-3, 1000, 0};  // E, nu, h, rho, T0
///   MembraneBoundary bc;    bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
///   MembraneLoads loads;    loads.pressure = 100;
///   MembraneSolver solver(mesh, opt, bc, loads);
///   MembraneSolveReport rep = solver.solveStatic();
///   double w0 = solver.summary().at("centreDeflection");
/// \endcode
///
/// State vectors are flat device Views with 3 entries per node (x, y, z).
#include "core/io/Checkpoint.hpp"
#include "structure/membrane/MembraneBending.hpp"
#include "structure/membrane/MembraneElements.hpp"
#include "structure/membrane/MembraneLinearSolve.hpp"

#include <array>
#include <map>
#include <string>

namespace mfsi {

/// \brief Outcome of a static solve or a time step.
struct MembraneSolveReport {
  bool converged = false;
  int iterations = 0;        ///< nonlinear iterations (summed over load steps)
  int linearIterations = 0;  ///< CG iterations (Newton)
  int lineSearchSteps = 0;   ///< residual evaluations beyond the first per Newton step
  real relativeResidual = 0;
  double seconds = 0;
};

/// \brief Nodal and element results (device Views).
struct MembraneResults {
  Real3View displacement;
  RealView displacementMagnitude;
  MembraneElementOutput elements;  ///< element-centre strain, PK2 stress, principal, von Mises, wrinkle state
};

/// \brief Springs from nodes to anchors at their reference positions (zero rest length: the
/// isotropic spring -k u).
std::vector<MembraneNodeSpring> makeAnchorSprings(const MembraneMesh& mesh, const std::vector<lid_t>& nodes,
                                                  real stiffness);

/// \brief A volume constraint on the implicit step: the membrane closes a region of incompressible
/// fluid whose volume change the inflow dictates. The step then also solves for one multiplier
/// lambda, a uniform follower pressure from the region's side, so that the region's volume change
/// from the reference configuration, sign * (the volume swept from it, membraneVolumeItems), equals `target`
/// at the end of the step. Newton on (u, lambda): two solves with the step's matrix A per
/// iteration (A a = r, A b = (1 - af) g, g = dV/du) and dlambda = -(c + g.a) / (g.b).
struct MembraneVolumeConstraint {
  bool active = false;
  /// +1: the region lies on the side the element normals point away from (its pressure pushes
  /// along them, and it grows as the membrane moves along them); -1: the other side.
  real sign = 1;
  real target = 0;        ///< the region's volume change at the end of the step [m^3 for a 3D mesh]
  real lambda = 0;        ///< the multiplier [Pa]: solved; the next solve starts from it
  real tolerance = 1e-12;  ///< |volume change - target| <= tolerance * A0 * lchar (A0 the reference area)
  /// The volume's response to the multiplier, d(volume change)/d(lambda) = g.b [m^3/Pa], of the last
  /// Newton iteration of the last constrained step (the step's dynamic stiffness, so it shrinks
  /// with the time step): what several membranes sharing one multiplier need to split a volume
  /// between them. Set by `solveStep`; 0 before.
  real compliance = 0;
};

/// \brief One membrane: mesh, options, boundary, loads and state.
class MembraneSolver {
 public:
  /// Throws InputError for invalid material, options or node ids in the boundary description.
  MembraneSolver(const MembraneMesh& mesh, const MembraneOptions& options, const MembraneBoundary& boundary = {},
                 const MembraneLoads& loads = {});

  const MembraneMesh& mesh() const { return mesh_; }
  const MembraneOptions& options() const { return options_; }
  /// Loads are mutable between solves (e.g. the coupling refills `nodePressure`).
  MembraneLoads& loads() { return loads_; }

  /// \brief Static equilibrium at time `time` (time functions, ramps and clamp frames are
  /// evaluated there), starting from the current displacement, with `options().loadSteps`
  /// increments. Sets the current time. Never throws on non-convergence: see the report.
  MembraneSolveReport solveStatic(real time = 0);

  /// \brief One implicit time step of size dt from the current state (Newton with the
  /// consistent tangent, whatever `options().solver`: the mass term keeps the matrix definite):
  /// `solveStep`, then `commitStep` when it converged.
  MembraneSolveReport step(real dt);

  // --- one step solved several times (FSI iterations) ----------------------------------------
  /// \brief Solve the step of size dt from the committed state (time(), displacement(),
  /// velocity(), acceleration(), all left unchanged) on the current loads. A repeated call for the
  /// same dt starts Newton from the last trial state. The result is the trial state.
  MembraneSolveReport solveStep(real dt);
  /// Trial state at time() + dt of the last `solveStep` (3 per node).
  RealView trialDisplacement() const { return uTrial_; }
  /// A trial state of this step is held (solveStep, adoptStep or setTrialDisplacement since the
  /// last commitStep or discardStep).
  bool hasTrial() const { return trial_.valid; }
  RealView trialVelocity() const { return v1_; }
  RealView trialAcceleration() const { return a1_; }
  /// \brief Replace the trial displacement (a relaxed FSI update); the trial velocity and
  /// acceleration follow from the integrator's relations.
  void setTrialDisplacement(const ConstRealView& u1);
  /// \brief The trial state becomes the state at time() + dt.
  void commitStep();
  /// \brief Forget the trial state (the next solveStep starts from the predictor).
  void discardStep();

  // --- a membrane solved on another rank ------------------------------------------------------
  /// \brief The Views a `solveStep` leaves its answer in: the trial displacement, velocity and
  /// acceleration, and the committed acceleration (which the first solve computes). A solver of
  /// the same membrane that did not run the solve (a rank mirroring a membrane its owner rank
  /// solves) receives the owner's values into its own four, then calls `adoptStep`: it then holds
  /// the owner's trial state bit for bit, and a `setTrialDisplacement` or `commitStep` on both
  /// gives the same state.
  std::array<RealView, 4> stepResult() const { return {uTrial_, v1_, a1_, a_}; }
  /// The step of size dt was solved elsewhere with `report` and the multiplier `lambda`.
  void adoptStep(real dt, const MembraneSolveReport& report, real lambda);
  /// A `solveStatic` at `time` was solved elsewhere (its displacement received into displacement()).
  void adoptStatic(real time, const MembraneSolveReport& report);

  /// The volume constraint of `solveStep` (inactive by default). Static solves refuse an active one.
  MembraneVolumeConstraint& volumeConstraint() { return volume_; }
  const MembraneVolumeConstraint& volumeConstraint() const { return volume_; }
  /// The weight of the loads of the step's start in its equilibrium: generalized-alpha's alpha_f
  /// (0 with Newmark). A body that shares the multiplier takes it weighted alike.
  real startLoadWeight() const { return integrator().af; }
  /// sign * (the volume the membrane swept from its reference to u): the constrained region's
  /// volume change at displacement u.
  real enclosedVolume(const ConstRealView& u);
  /// The volume misses the constrained solves and projectOntoVolume accept [m^3].
  real volumeTolerance() const;
  /// \brief Move u along the (constrained) volume gradient until enclosedVolume(u) = target to the
  /// constraint's tolerance (a relaxed FSI iterate the fluid must be able to follow). Returns the
  /// largest nodal move.
  real projectOntoVolume(const RealView& u);
  /// \brief Add `delta` to the multiplier, of the committed state too: another module took over
  /// -delta of the uniform pressure (a fluid whose pressure level was raised by it).
  void shiftMultiplier(real delta) {
    volume_.lambda += delta;
    lambdaCommitted_ += delta;
  }

  /// \brief Artificial added mass of an FSI coupling iteration [kg/m^2] (0: off). Each `solveStep`
  /// then adds m_i (a_1 - a_1*) to the inertia, m_i = massPerArea x the node's lumped area, with
  /// a_1* the acceleration of the displacement the solve starts from (the interface iterate the
  /// fluid saw, in a coupling iteration: `setTrialDisplacement`). The term vanishes once the
  /// coupling has converged (the solve then returns the displacement it started from), so the
  /// answer is unchanged; what changes is the fixed-point map: a light membrane in a dense fluid
  /// no longer answers a pressure change with the large move that only the fluid's added mass,
  /// which the partitioned structure solve does not see, would hold back.
  void setInterfaceMass(real massPerArea);
  /// The lumped nodal masses rho h A_i [kg] (one per node; computed once).
  RealView nodalMass();
  real interfaceMass() const { return interfaceMass_; }

  real time() const { return time_; }
  void setTime(real t) { time_ = t; }
  /// Displacement (writable: initial conditions); call `resetDynamics()` after editing u or v.
  RealView displacement() const { return u_; }
  RealView velocity() const { return v_; }
  RealView acceleration() const { return a_; }
  /// Forget the stored acceleration; the next `step` recomputes it from M a = R - C v.
  void resetDynamics() {
    haveAcceleration_ = false;
    trial_ = {};
  }

  /// \brief Results at the current state.
  MembraneResults results();
  /// \brief Scalar metrics: maxDisplacement, centreDeflection (along the reference normal of the
  /// "centre" node), maxVonMises, maxPrincipalStress, minPrincipalStress, wrinkledFraction and
  /// slackFraction (of the reference area), iterations and relativeResidual of the last solve, time.
  std::map<std::string, double> summary();
  const MembraneSolveReport& lastReport() const { return last_; }

  // --- checkpoints ---------------------------------------------------------------------------
  /// \brief Write what a later `step`, `solveStep` or `solveStatic` reads, so a solver built from
  /// the same mesh, options and boundary continues bitwise after `loadState`: time, displacement,
  /// velocity, acceleration (and whether it is set), the trial state of an uncommitted step (a warm
  /// start), the last report, and the load fields it holds (nodePressure, elementPressure,
  /// nodeForce). Not written: what the options or the boundary define (uniform pressure, time
  /// functions, clamp frames) and what is recomputed from the state (mass, damping matrix).
  void saveState(io::StateWriter& w) const;
  /// \brief Read what `saveState` wrote. A load field in the checkpoint is copied into the View
  /// the loads hold (a coupling that shares it gets it back) or into a new one. Throws InputError
  /// naming the checkpoint and dataset when it does not fit (another mesh).
  void loadState(const io::StateReader& r);

  // Building blocks, public for tests, benchmarks and coupling.

  /// \brief R = f_ext - f_int (unprojected; at fixed nodes -R is the support reaction) at the
  /// current displacement, loads at `time` scaled by loadFactor.
  RealView residual(real time, real loadFactor = 1);
  /// \brief Newton matrix at the current displacement and loads at `time` (CSR, all rows).
  const CsrMatrix& assembleTangent(real time, bool withPressureStiffness = true);
  /// \brief Consistent mass matrix (CSR, same sparsity as the tangent).
  const CsrMatrix& assembleConsistentMass();
  const CsrAssemblyMap& assemblyMap() const { return map_; }
  const MembraneConstraints& constraints() const { return constraints_; }
  real characteristicLength() const { return lchar_; }

 public:
  // --- the steps of the solves -------------------------------------------------------------
  // Public only because nvcc compiles extended device lambdas (KOKKOS_LAMBDA) solely in public
  // member functions (CUDA Programming Guide, extended-lambda restrictions). They expect the state
  // the solves above set up around them: not API.
  struct Norms {
    real free = 0, reaction = 0, external = 0;
  };

  void setupItems();
  void setupConstraints();
  void setupClamps();
  void updatePressure(real time, real loadFactor);
  MembranePressureKernel pressureKernel(bool withStiffness) const;
  void evalResidual(const ConstRealView& u, real time, real loadFactor);
  void assembleTangentAt(const ConstRealView& u, bool withPressure);
  void clampTargets(real time);
  void applyClamps(const RealView& u, real weight);
  Norms norms(const ConstRealView& r);
  /// |free residual| / max(loads, reactions, initialFree, residualFloor / tolerance).
  real relativeResidual(const Norms& q, real initialFree) const;
  /// Round-off level of the internal nodal forces, 1e-13 E h lchar [N]: a residual below it is
  /// converged whatever the loads (a slack membrane under a vanishing load).
  real residualFloor() const {
    return 1e-13 * options_.material.youngsModulus * options_.material.thickness * lchar_;
  }
  /// Newmark / generalized-alpha coefficients of the options.
  struct Integrator {
    real am = 0, af = 0, beta = 0.25, gamma = 0.5;
  };
  Integrator integrator() const;
  /// a1_, v1_ from uTrial_ and the committed state.
  void trialKinematics();
  real maxNodalNorm(const ConstRealView& d);

  /// enclosedVolume(u) and, into `gradient` (3 per node), its gradient.
  real enclosedVolumeAt(const ConstRealView& u, const RealView& gradient);
  MembraneSolveReport newtonSolve(real time, real loadFactor);
  MembraneSolveReport lumpedSolve(real time, real loadFactor);

 private:
  MembraneMesh mesh_;
  MembraneOptions options_;
  MembraneBoundary boundary_;
  MembraneLoads loads_;
  MembraneReferenceGeometry geometry_;
  MembraneElementData data_;
  MembraneLineItems lines_;
  MembraneHinges hinges_;  ///< bending (material.bending), item rows from hingeItem0_
  lid_t hingeItem0_ = 0;
  CsrAssemblyMap map_;
  CsrMatrix K_, M_, Kdamp_;
  MembraneConstraints constraints_;
  MembraneCg cg_;
  ExecSpace exec_;

  lid_t nItems_ = 0;
  real lchar_ = 1;
  real time_ = 0;
  bool haveAcceleration_ = false;
  bool haveMass_ = false;
  MembraneSolveReport last_;
  /// The trial state of solveStep: whether it holds one, and its step size.
  struct Trial {
    bool valid = false;
    real dt = 0;
  };
  Trial trial_;

  ItemValuesView itemVec_, itemExt_, itemMat_;
  RealView u_, v_, a_, R_, Fext_, du_, uTrial_, work_, work2_, rn_, lumpedMass_, pNode_, offsetSign_;
  RealView a1_, v1_, rhs_, dampingForce_;  ///< time-step work vectors
  MembraneVolumeConstraint volume_;
  real lambdaCommitted_ = 0;  ///< the multiplier at time(): generalized-alpha's R_n carries it
  RealView volumeGrad_, volumeDu_;  ///< g and b of the constrained Newton step
  RealView lineStart_;  ///< the Newton iterate a time step's line search starts from
  real interfaceMass_ = 0;            ///< artificial added mass per area (setInterfaceMass)
  RealView interfaceNodeMass_, anchor_;  ///< its nodal masses per dof; the displacement a solve starts from
  RealView nodalMass_;                ///< nodalMass()
  RealView pElem_, pElemScaled_;  ///< element pressure in use (the load field, or a scaled copy)
  // Clamps: node ids, reference-frame targets at the requested time, start values of a load ramp.
  IndexView clampNodes_;
  Kokkos::View<real* [3], MemSpace> clampTarget_, clampStart_;
  std::vector<std::pair<int, lid_t>> clampHost_;  ///< (clamp group, node)
};

}  // namespace mfsi
