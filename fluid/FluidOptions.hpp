#pragma once
/// \file
/// \brief Plain options of the incompressible ALE finite-volume fluid solver. A config layer fills
/// these from YAML; the solver never sees the parser.
#include "core/Types.hpp"
#include "fluid/FvAssembly.hpp"

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mfsi::fluid {

using Vec3 = std::array<real, 3>;

/// \brief Time discretisation.
enum class TimeScheme {
  Steady,  ///< no time derivative; SIMPLE iterations with under-relaxation (`PimpleOptions::relax*`)
  Euler,   ///< implicit Euler (first order)
  BDF2,    ///< second-order backward differences, volume-weighted for moving meshes (Euler on step 1)
};

/// \brief Interpolation of the convected velocity to faces.
enum class ConvectionScheme {
  Upwind,         ///< first-order upwind, implicit
  Linear,         ///< central (linear interpolation), implicit
  LimitedLinear,  ///< TVD blend of upwind and linear (limiter min(2r, 1)), deferred correction on upwind
  VanLeer,        ///< TVD van Leer limiter, deferred correction on upwind
};

/// \brief Cell gradient reconstruction.
enum class GradientScheme {
  GaussLinear,   ///< Green-Gauss with linearly interpolated face values
  LeastSquares,  ///< inverse-distance-weighted least squares over face neighbours and boundary faces
};

/// \brief Pressure value at walls and other faces with a prescribed velocity (the face flux there
/// is fixed, so this value only enters the cell pressure gradient and the loads).
enum class WallPressure {
  /// p_b = p_P + grad(p)_P . (x_b - x_P) with the latest gradient: consistent for linear pressure
  /// (hydrostatics, accelerating columns) and second order for the wall loads
  Extrapolated,
  /// p_b = p_P: halves the normal gradient in wall cells, a first-order error in those cells
  ZeroGradient,
};

/// \brief Kind of a fluid boundary condition on a patch.
enum class BoundaryType {
  Auto,           ///< from the mesh patch kind: wall -> Wall, symmetry -> Slip, empty -> Empty, baffle sides -> Wall
                  ///< with `WallMotion::External`; a plain patch without an entry is an error
  FixedVelocity,  ///< prescribed velocity (`velocity` x profile x time function); zero-gradient/fixed-flux pressure
  FlowRate,       ///< prescribed volumetric inflow `flowRate` x time function, along the inward normal, with a profile
  Wall,           ///< impermeable wall; tangential velocity from `wallMotion`, normal velocity = mesh velocity
  Slip,           ///< free slip / symmetry plane (moves with the mesh)
  Empty,          ///< front and back of a one-cell-thick 2D mesh: no flux of anything
  FixedPressure,  ///< p = pressure x time function, zero-gradient velocity (outflow)
  Resistance,     ///< p = resistance * q + pressure, q the outflow rate through the patch (explicit in q)
};

/// \brief Spatial shape of a prescribed velocity or flow rate on a patch.
enum class Profile {
  Uniform,    ///< constant over the patch
  Parabolic,  ///< prod over `parabolicAxes` of 4 s (1 - s), s in [0, 1] across the patch extent, peak 1
  Linear,     ///< prod over `parabolicAxes` of s: 0 at the low end of the extent, 1 at the high end
  Function,   ///< `velocityFunction(x, t)` (FixedVelocity only; the time function still multiplies it)
};

/// \brief Scalar time modulation f(t) of a boundary value.
struct TimeFunction {
  enum class Kind {
    Constant,     ///< f = 1
    OneMinusCos,  ///< f = 1 - cos(2 pi t / period)
    CosineRamp,   ///< f = (1 - cos(pi t / period)) / 2 for t < period, then 1
    Function,     ///< f = fn(t)
    /// Half-power sine pulse (ventricular-assist-device inflow): with tau = t mod period,
    /// f = sin(pi tau / pulseDuration)^exponent for tau < pulseDuration, else 0 (or a second
    /// pulse, secondAmplitude). The amplitude A is the boundary value the function multiplies
    /// (velocity, flow rate or pressure).
    HalfPowerSine,
  };
  Kind kind = Kind::Constant;
  real period = 1.0;
  std::function<real(real)> fn;
  /// HalfPowerSine: duration Tp of the pulse within one period, in (0, period]; 0 means period / 2.
  real pulseDuration = 0.0;
  /// HalfPowerSine: exponent p of the sine (> 0); 0.5 gives the "half-power" sine.
  real exponent = 0.5;
  /// HalfPowerSine: a second pulse right after the first, for Tp <= tau < Tp + secondDuration:
  /// f = secondAmplitude sin(pi (tau - Tp) / secondDuration)^exponent (a pump's ejection then
  /// filling: secondAmplitude < 0). 0: none.
  real secondAmplitude = 0.0;
  real secondDuration = 0.0;

  /// \brief Value at time t.
  real operator()(real t) const;
};

/// \brief Where a wall's tangential velocity comes from.
enum class WallMotion {
  Fixed,         ///< `PatchBC::velocity` x time function (zero: no-slip; e.g. a driven lid)
  MeshVelocity,  ///< the velocity of the mesh nodes of the face (walls that move with the mesh)
  External,      ///< per-face values given by `FluidSolver::setWallVelocity` (membranes on baffles)
};

/// \brief Boundary condition of one patch.
struct PatchBC {
  BoundaryType type = BoundaryType::Auto;
  Vec3 velocity{0, 0, 0};  ///< FixedVelocity: value (peak for Parabolic); Wall + Fixed: wall velocity
  Profile profile = Profile::Uniform;
  std::array<bool, 3> parabolicAxes{false, false, false};  ///< axes the parabola varies across
  /// Parabola extent per axis; if min >= max on an axis the patch's bounding box is used.
  Vec3 parabolicMin{0, 0, 0};
  Vec3 parabolicMax{0, 0, 0};
  std::function<Vec3(const Vec3& x, real t)> velocityFunction;  ///< Profile::Function
  real flowRate = 0;          ///< FlowRate: volumetric inflow [m^3/s] (positive into the domain)
  real pressure = 0;          ///< FixedPressure: p; Resistance: p0 [Pa]
  real resistance = 0;        ///< Resistance: C_r [Pa s / m^3]
  TimeFunction timeFunction;  ///< multiplies the velocity, flow rate or pressure
  WallMotion wallMotion = WallMotion::Fixed;
  /// \brief FixedPressure / Resistance: a valve. Open (the pressure condition) while
  /// openFrom <= t mod period < openTo, closed (a no-slip wall, no flow) otherwise; period 0: always open.
  struct Valve {
    real period = 0, openFrom = 0, openTo = 0;
    bool open(real t) const;
  };
  Valve valve;
};

/// \brief Preconditioner of the pressure equation's conjugate gradients.
enum class PressurePreconditioner {
  Amg,     ///< smoothed-aggregation algebraic multigrid (kernels/Amg.hpp), mesh-independent iterations
  Jacobi,  ///< diagonal scaling
};

/// \brief Stopping rule of one linear solve: scaled residual (OpenFOAM's normalisation, see
/// fluid/LinearSolve.hpp) below `tolerance`, or 2-norm reduced by `relTol`, or `maxIter`.
struct LinearSolverOptions {
  real tolerance = 1e-8;
  real relTol = 0.0;
  int maxIter = 2000;
  /// AMG preconditioner only: smoother applications on its finest level for this solve (0: its
  /// default, one).
  int amgFinestSweeps = 0;
};

/// \brief Pressure-velocity coupling (PIMPLE; with TimeScheme::Steady it is SIMPLE).
struct PimpleOptions {
  int nOuterCorrectors = 1;          ///< outer iterations per step (SIMPLE iterations when steady)
  int nCorrectors = 2;               ///< pressure correctors per outer iteration (PISO)
  int nNonOrthogonalCorrectors = 0;  ///< extra pressure solves for the explicit non-orthogonal correction
  bool momentumPredictor = true;
  /// Outer loop stops early when the initial residuals of momentum and pressure drop below this.
  real outerTolerance = 0.0;
  real relaxVelocity = 1.0;  ///< implicit under-relaxation of momentum (use ~0.7 when steady)
  real relaxPressure = 1.0;  ///< explicit under-relaxation of pressure (use ~0.3 when steady)
  /// SIMPLEC (steady only): the pressure equation and the velocity correction use
  /// rAtU = V / (a_P - H1) (a_P the relaxed diagonal, H1 the negated sum of the row's
  /// off-diagonal coefficients) instead of rAU = V / a_P, with the pressure gradient's part
  /// of HbyA and phiHbyA moved over to match, so the converged fluxes are SIMPLE's. Neighbour
  /// corrections the SIMPLE approximation drops are kept, and pressure needs no under-relaxation.
  bool consistent = false;
  /// Rhie-Chow correction of the time-derivative term (face fluxes remember their own history), so
  /// results do not depend on dt through the interpolation.
  bool ddtCorrection = true;
  /// Initial guesses only (every solve still stops on its own tolerance): the first momentum
  /// predictor of a time step starts from U extrapolated linearly in time from the two previous
  /// steps instead of from the last step's U, and the final pressure corrector starts from the
  /// pressure of the corrector before it plus the change the final corrector made at the last solve.
  /// Both start closer to the answer, so the solves need fewer iterations (3D cavity, 64^3:
  /// momentum 8.5 -> 6.5, pressure 9.4 -> 8.5 iterations per step).
  bool extrapolateGuess = true;
  /// With extrapolateGuess: the final pressure corrector adds the best multiple s of the last
  /// final change instead of all of it (s minimising the energy norm of the guess's error on this
  /// step's matrix and source; one extra pass over the matrix). 3D cavity 64^3: 6.53 instead of
  /// 7.27 pressure iterations per step. Off: s = 1 (for comparison; not a scene key).
  bool projectFinalGuess = true;
};

/// \brief Artificial (weak) compressibility of the continuity equation: (1 / (rho c^2)) dp/dt +
/// div(u) = 0 with an artificial sound speed c. Damps the added-mass instability of partitioned
/// FSI with enclosed or nearly enclosed fluids, and makes the pressure level well defined without
/// a pressure boundary. c -> infinity recovers the incompressible equations.
struct ArtificialCompressibilityOptions {
  real soundSpeed = 0.0;  ///< c [m/s]; 0 switches the term off (incompressible). Ignored when steady.
};

/// \brief Time means of U and p accumulated by a run, weighted by the time step (OpenFOAM's
/// fieldAverage mean). Read by the module that runs the solver, not by the solver.
struct RunningMeanOptions {
  bool enabled = false;
  real start = 0.0;  ///< steps that end at or after this time [s] enter the means
};

/// \brief A fluid of its own in the cells a patch reaches (core/MeshRegions: cells joined through
/// internal faces, so a baffle across the domain parts two regions): the air chamber behind a
/// membrane whose other side holds blood. Its faces never touch another fluid's (the baffle's two
/// sides are boundary faces), so the pressure stays the dynamic pressure [Pa] in every region.
struct FluidRegion {
  std::string patch;      ///< every region with a face on this patch
  real density = 1.0;     ///< rho [kg/m^3]
  real viscosity = 0.01;  ///< mu [Pa s]
};

/// \brief All options of `FluidSolver`.
struct FluidOptions {
  real density = 1.0;       ///< rho [kg/m^3] (of the cells no `regions` entry names)
  real viscosity = 0.01;    ///< dynamic viscosity mu [Pa s] (likewise)
  std::vector<FluidRegion> regions;  ///< other fluids, each in the regions its patch reaches
  Vec3 bodyForce{0, 0, 0};  ///< body acceleration g [m/s^2]
  TimeScheme timeScheme = TimeScheme::BDF2;
  ConvectionScheme convection = ConvectionScheme::Linear;
  GradientScheme gradient = GradientScheme::GaussLinear;
  /// OpenFOAM's `limited psi` surface-normal gradient: each face's explicit non-orthogonal
  /// correction is at most psi / (1 - psi) times its orthogonal part (pressure equation, its face
  /// fluxes and the viscous term). 1 = fully corrected, 0 = uncorrected, 0.5 = the correction at
  /// most as large as the orthogonal part.
  real nonOrthogonalLimit = 1.0;
  WallPressure wallPressure = WallPressure::Extrapolated;
  ReductionMode reduction = ReductionMode::Gather;
  /// Use the fused per-cell passes where valid: momentum matrix and source (orthogonal mesh, linear
  /// or upwind convection, Gather reduction), pressure matrix and end-of-step pass (Gather),
  /// pressure source flux without phiHbyA (orthogonal mesh), pressure gradient with its boundary
  /// pressures in one pass (Gather, Gauss linear), final face fluxes with the correction fluxes;
  /// and skip the face fluxes of correctors that the next one overwrites unread. They give the
  /// same fields bitwise as the face-coefficient paths; false forces those paths (verification,
  /// perf comparison). Not a scene key.
  bool fusedMomentumAssembly = true;
  PimpleOptions pimple;
  LinearSolverOptions momentumSolver{1e-10, 0.0, 1000};
  LinearSolverOptions pressureSolver{1e-10, 0.0, 5000};
  /// relTol of the final pressure solve of a step (last corrector of the last outer iteration,
  /// OpenFOAM's pFinal); negative: the same as pressureSolver.relTol.
  real pressureFinalRelTol = -1.0;
  /// AMG smoother applications on the finest level in the pressure solves before the final one of
  /// a step (the final one uses one). Those solves stop at relTol; a second application there
  /// costs ~1.4 ms per V-cycle on the 64^3 cavity (1 thread) and ends icoFoam's relTol = 0.05 solve after 2
  /// instead of 3 AMG-CG iterations (after 2 with one application its residual is 0.05-0.1 of the
  /// initial one). In the final solve it saves ~0.1 iterations, less than it costs.
  int pressureFinestSweeps = 2;
  PressurePreconditioner pressurePreconditioner = PressurePreconditioner::Amg;
  /// On a decomposed mesh, the pressure solve's halo exchanges run while its products multiply
  /// the rows that read no ghost (see kernels/Blas spmvDotOverlapped, DistributedAmgOptions);
  /// false: exchange first. The same results bit for bit. Off by default: on one shared-memory
  /// node the transfers take 2-5 % of a step, mostly waits for the other rank that no overlap
  /// hides, and the split products cost 1-3 % more (perf/RESULTS.md).
  bool overlapHalo = false;
  /// Most outer iterations between value refreshes of the pressure preconditioner, counted across
  /// time steps (the first solve always sets it up). A slightly stale AMG hierarchy is still a
  /// good, fixed SPD preconditioner, and its refresh costs about as much as a solve, so it is also
  /// refreshed early only when it has gone stale: when a step's final pressure solve needs more
  /// than `pressurePreconditionerStaleRatio` times (plus one) the iterations of the first final
  /// solve after the last refresh. Jacobi is refreshed every outer iteration regardless.
  int pressurePreconditionerRefresh = 50;
  real pressurePreconditionerStaleRatio = 1.25;
  /// Used only when no boundary fixes the pressure level.
  lid_t pressureReferenceCell = 0;
  real pressureReferenceValue = 0;
  Vec3 initialVelocity{0, 0, 0};
  real initialPressure = 0;
  ArtificialCompressibilityOptions artificialCompressibility;
  /// Runaway-growth guard of a run (fluid/RunawayGuard.hpp): once per time step, the run stops as
  /// diverged when max |U| over the cells exceeds this factor times the velocity scale of the
  /// scene's boundary conditions. 0 switches it off. The solver itself does not read it.
  real divergenceVelocityFactor = 100.0;
  /// Running time means UMean, pMean (fluid/RunningMean.hpp).
  RunningMeanOptions means;
  /// Boundary condition per patch name (patches of kind wall/symmetry/empty/baffle may be omitted).
  std::map<std::string, PatchBC> boundaries;
};

const char* toString(TimeScheme s);
const char* toString(ConvectionScheme s);
const char* toString(BoundaryType t);

}  // namespace mfsi::fluid
