#pragma once
/// \file
/// \brief Runaway-growth guard: once per step, the largest cell velocity against the velocity scale
/// the scene's boundary conditions impose (`FluidOptions::divergenceVelocityFactor`).
///
/// Why: an unstable discretisation (too large a time step for the pressure-velocity coupling, too
/// little under-relaxation) can multiply the velocity by orders of magnitude per step and still
/// stay finite for many steps, so a check for NaN/Inf alone lets such a run end "ok" with
/// |U| = 1e19 in a cavity whose lid moves at 1 m/s. A flow driven by its boundaries, its initial
/// state, pressure differences and gravity stays within a modest multiple of the velocities these
/// impose; a hundred times that is a blow-up, not physics.
///
/// The scale is the largest of
///   - the prescribed boundary velocities at the peak of their time functions: fixedVelocity and
///     wall velocities (a parabolic or linear profile peaks at the given value), flow rates divided
///     by the patch area times the profile's peak-to-mean ratio (1.5 per parabolic axis, 2 per
///     linear axis);
///   - |initial velocity|;
///   - sqrt(2 dp / rho), dp the range of the prescribed pressures (over their time functions) and
///     the initial pressure;
///   - sqrt(2 |g| L), g the body acceleration and L the diagonal of the mesh's bounding box;
///   - the largest velocity a boundary has imposed at a check so far in the run: prescribed face
///     velocities as evaluated (velocity profiles given as functions), walls moving with the mesh,
///     membranes (external wall velocities) and the mesh velocity of every boundary face; and the
///     pressure scale of the prescribed pressures as evaluated. Kept as a running maximum so that
///     a wall at rest at its turning point does not shrink the scale of a flow it set in motion.
/// With a scale of zero (nothing drives the flow) there is nothing to compare with: no check.
#include "core/io/Checkpoint.hpp"
#include "fluid/FluidSolver.hpp"

namespace mfsi::fluid {

/// \brief Velocity scales [m/s] a scene prescribes for all time, from the options and the
/// reference geometry (see the file comment).
struct PrescribedVelocityScale {
  real boundary = 0;  ///< prescribed boundary velocities at the peak of their time functions
  real initial = 0;   ///< |initial velocity|
  real pressure = 0;  ///< sqrt(2 dp / rho) over the prescribed and initial pressures
  real gravity = 0;   ///< sqrt(2 |g| L)
  /// \brief The largest of the four.
  real value() const;
};

/// \brief The scales `fluid`'s options and boundary conditions prescribe (host; reads the
/// reference points and boundary face areas once).
PrescribedVelocityScale prescribedVelocityScale(const FluidSolver& fluid);

/// \brief Largest |u| the boundaries impose now (device reduction `mfsi::fluid::runaway::boundary`):
/// the prescribed velocity of velocity and wall faces (inlets, lids, walls moving with the mesh,
/// membranes) and the mesh velocity of every boundary face.
real boundaryVelocityNow(const FluidSolver& fluid);

/// \brief max over cells of |U| [m/s] (device reduction `mfsi::fluid::maxVelocity`).
real maxVelocity(const FluidSolver& fluid);

/// \brief The guard of one run: the prescribed scale, the running maximum of what the boundaries
/// imposed, and the factor.
class RunawayGuard {
 public:
  RunawayGuard() = default;
  /// \brief Guard for `fluid` with `factor` (0: off).
  RunawayGuard(const FluidSolver& fluid, real factor);

  /// \brief Once per step, after its last solve (step from `time` to `time + dt`): update the
  /// running boundary maximum and throw DivergenceError naming max |U|, the scale, the time and
  /// what to change when max |U| > factor x scale().
  void check(const FluidSolver& fluid, real time, real dt);

  bool enabled() const { return factor_ > 0; }
  real factor() const { return factor_; }
  /// The velocity scale now: max(prescribed().value(), largest boundary velocity seen).
  real scale() const;
  const PrescribedVelocityScale& prescribed() const { return prescribed_; }
  /// max |U| at the last check (0 before the first).
  real lastMaxVelocity() const { return lastMax_; }

  /// \brief The running maximum and the last max |U| (the prescribed part is rebuilt from the scene).
  void saveState(io::StateWriter& w) const;
  void loadState(const io::StateReader& r);

 private:
  real factor_ = 0;
  PrescribedVelocityScale prescribed_;
  real boundarySeen_ = 0;  ///< largest boundary-imposed velocity (or evaluated pressure scale) at a check
  real lastMax_ = 0;
};

}  // namespace mfsi::fluid
