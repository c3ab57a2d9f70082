#pragma once
/// \file
/// \brief Config layer of the `coupling` section: its schema (the seed's parameter names) and the
/// plain options the orchestrator runs with. The orchestrator never sees the scene.
///
/// \code{.yaml}
/// coupling:
///   scheme: implicit        # implicit (Gauss-Seidel iterations, structure first) | explicit (one pass)
///   fsiTol: 1.0e-5          # relative interface residuals: max(|dx|/|x|, |df|/|f|)
///   minFsiIter: 1
///   maxFsiIter: 30
///   omegaInit: 0.5          # Aitken's first relaxation of a step
///   omegaMin: 0.05
///   iqnMaxCols: 30          # > 0: IQN-ILS instead of Aitken
///   iqnReuseCols: 0         # past steps whose columns IQN-ILS reuses
///   forceOmega: 1           # under-relaxation of the membrane load between iterations
///   pNetFilterTau: 0        # low-pass of the load in time (s), once per step
///   pNetSmoothIter: 0       # conservative smoothing of the load over the surface
///   fsiStartTime: 0         # structure frozen before this time
///   fsiRampTime: 0          # load ramp 0 -> 100 % after fsiStartTime
///   outsidePressure: 0      # pressure behind a membrane that replaces a wall patch
///   interfaceMass: 0        # artificial added mass (kg/m^2) of a coupling iteration, gone at convergence
///   volumeConstraint: true  # a membrane closing an incompressible fluid with no pressure boundary keeps its volume in step with the inflow
///   lumpedChamber: {membrane: diaphragm, flowRate: 3.19e-4, timeFunction: {...}}  # an unmeshed gas chamber behind a membrane
///   meshMotion: {sweeps: 50, minScaledJacobian: 0.05, bodies: {frame: {innerDistance: 0.1, outerDistance: 0.5}}}
///   bodyPatches: {piston: [pistonFace]}   # rigid bodies (the `bodies` section) and the fluid patches they carry
///   parentBodyPatches: {sail: [mast]}     # membranes mounted on those bodies (nearest listed patch)
/// \endcode
#include "core/SceneConfig.hpp"
#include "coupling/acceleration/Acceleration.hpp"
#include "coupling/motion/MeshSmoother.hpp"
#include "fluid/FluidOptions.hpp"

namespace mfsi {

/// Implicit: Gauss-Seidel iterations to convergence per step; explicit: one staggered pass.
enum class CouplingScheme { Implicit, Explicit };

/// Which interface residuals must fall below fsiTol.
enum class CouplingConvergence {
  Displacement,  ///< |x~ - x| / |x~| alone
  Both,          ///< and the load change |f_k - f_{k-1}| / |f_k| (the seed's max of both)
};

/// \brief Everything the `coupling` section describes.
struct CouplingOptions {
  CouplingScheme scheme = CouplingScheme::Implicit;
  CouplingConvergence convergence = CouplingConvergence::Both;
  double fsiTol = 1e-5;
  int minFsiIter = 1;   ///< fluid solves per step, at least
  int maxFsiIter = 30;  ///< fluid solves per step, at most
  /// maxFsiIter reached on this many steps in a row stops the run as diverged.
  int maxUnconvergedSteps = 3;
  coupling::AccelerationOptions acceleration;
  double forceOmega = 1;      ///< load under-relaxation between iterations (1: none)
  double pNetFilterTau = 0;   ///< s: low-pass of the load in time, alpha = dt / (tau + dt), state kept per step (0: off)
  int pNetSmoothIter = 0;     ///< conservative smoothing steps of the load over the membrane surface
  double fsiStartTime = 0;    ///< s
  double fsiRampTime = 0;     ///< s
  double pClamp = 0;          ///< |pNet| limit [Pa] (0: none)
  double outsidePressure = 0; ///< Pa
  double interfaceMass = 0;   ///< kg/m^2: artificial added mass of a coupling iteration (0: off)
  /// Limit of a body's centre-of-mass move per coupling iteration, over the time step [m/s] (0: off).
  double maxMeshVelocity = 0;
  /// Limit of a membrane node's move per coupling iteration, as a fraction of the membrane's
  /// characteristic length sqrt(reference area) (0: off): the seed's bow-limiter.
  double maxDeltaDispFrac = 0;
  bool viscousTraction = false;  ///< add the fluid's viscous traction to the membrane loads
  /// A fluid domain with no pressure boundary (incompressible): the membrane patch that closes it
  /// solves with a volume constraint (core/MeshRegions).
  bool volumeConstraint = true;
  /// \brief A gas chamber behind a membrane patch that is not meshed (its inertia negligible: the
  /// pump's air chamber): one uniform pressure, the membrane's volume constraint's multiplier, and a
  /// volume that grows by the integral of the prescribed inflow over each step.
  struct LumpedChamber {
    std::string membrane;  ///< empty: none
    double flowRate = 0;   ///< m^3/s into the chamber, times the time function
    fluid::TimeFunction timeFunction;
  };
  LumpedChamber lumpedChamber;
  /// Every coupling iteration's fluid solve starts from the step's start iterate (true) instead of
  /// the last iteration's answer: the fluid's answer is then a function of the interface alone,
  /// also where the fluid does not converge within its outer iterations.
  bool fluidFromStepStart = false;
  /// The structure's predictor solve of a step takes the fluid's load at t_n (false) or its linear
  /// extrapolation to t_n+1 from t_n and t_n-1, 2 p_n - p_n-1 (true): a first iterate closer to the
  /// step's answer where the load changes steadily (a travelling pressure wave).
  bool extrapolatedPredictor = false;
  coupling::MeshSmootherOptions motion;
  /// \brief A rigid body of the `bodies` section and the fluid patches that move with it.
  struct BodyPatches {
    std::string body;
    std::vector<std::string> patches;
  };
  std::vector<BodyPatches> bodyPatches;  ///< empty: no body is coupled
  /// \brief How far a coupled body carries the mesh rigidly (`meshMotion.bodies`, coupling/motion/RigidBlend).
  struct BodyReach {
    std::string body;
    double innerDistance = 0;
    double outerDistance = 0;
  };
  std::vector<BodyReach> bodyReach;  ///< empty: the Laplacian alone carries the bodies' motion
  /// \brief A membrane mounted on moving bodies: each of its nodes follows the body whose listed
  /// patch (one of bodyPatches') is nearest, and its FEM displacement is relative to that body.
  struct ParentPatches {
    std::string membrane;
    std::vector<std::string> patches;
  };
  std::vector<ParentPatches> parentBodyPatches;
};

/// Schema of the `coupling` section.
Schema couplingSchema();

/// Options of a view of the `coupling` section. Throws InputError naming the key on semantic
/// errors (minFsiIter > maxFsiIter).
CouplingOptions readCouplingOptions(const SceneConfig& coupling);

}  // namespace mfsi
