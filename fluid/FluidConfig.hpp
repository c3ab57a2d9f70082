#pragma once
/// \file
/// \brief Config layer of the `fluid` section: its schema, the `FluidOptions` it describes, and the
/// reports (patch forces, pressure differences, Ghia comparison) a run computes from the solution.
/// The fluid solver never sees the scene.
///
/// \code{.yaml}
/// fluid:
///   density: 1.0                 # kg/m^3
///   nu: 0.01                     # kinematic viscosity m^2/s (or `viscosity`: dynamic, Pa s)
///   timeScheme: steady           # steady | euler | bdf2
///   convection: linear           # upwind | linear | limitedLinear | vanLeer
///   pimple: {outerCorrectors: 200, correctors: 1, relaxVelocity: 0.9, relaxPressure: 0.2}
///   solvers:
///     pressure: {preconditioner: amg, tolerance: 1e-9, relTol: 0.01}
///     momentum: {tolerance: 1e-9, relTol: 0.01}
///   boundary:
///     inlet:  {type: fixedVelocity, velocity: [0.3, 0, 0], profile: parabolic, parabolicAxes: [y]}
///     outlet: {type: fixedPressure, pressure: 0}
///     lid:    {type: wall, velocity: [1, 0, 0]}
///   forces:
///     - {patch: cylinder, referenceVelocity: 0.2, referenceArea: 0.001}
///   pressureDifferences:
///     - {name: dp, from: [0.15, 0.2, 0], to: [0.25, 0.2, 0], patch: cylinder}
///   flows: [inlet, outlet]       # flow rate and mean pressure of each, every step
///   meanPressure: true           # the volume-weighted mean pressure, every step
///   ghia: {re: 100, lidSpeed: 1}
///   divergenceVelocityFactor: 100  # stop as diverged when max |U| > 100 x the scene's velocity scale
///   means: {start: 5}              # UMean, pMean from t = 5 on, in the field output
/// \endcode
#include "core/HexMesh.hpp"
#include "core/SceneConfig.hpp"
#include "fluid/FluidOptions.hpp"

#include <string>
#include <vector>

namespace mfsi {

/// Schema of the `fluid` section.
Schema fluidSchema();

/// \brief Schema of a time function f(t) (`fluid.boundary.<patch>.timeFunction`, and wherever
/// another section prescribes a time history), described as `what`.
Schema timeFunctionSchema(const std::string& what);
/// \brief The time function a `timeFunctionSchema` section describes. Throws InputError naming the
/// key for pulses that do not fit in the period.
fluid::TimeFunction readTimeFunction(const SceneConfig& section);

/// Options described by a view of the `fluid` section, checked against the patches of `mesh`.
/// Throws InputError naming the scene key on semantic errors (unknown patch, a plain patch without
/// a condition, both or neither of viscosity/nu, a parabolic profile without axes).
fluid::FluidOptions readFluidOptions(const SceneConfig& fluidSection, const HexMesh& mesh);

/// \brief Force and moment on a patch (or both sides of a baffle), with coefficients
/// c = 2 F.e / (rho U^2 A) along the drag and lift directions when `referenceVelocity` > 0.
struct ForceReport {
  std::string patch;
  fluid::Vec3 point{0, 0, 0};    ///< moment reference point [m]
  double referenceVelocity = 0;  ///< U [m/s]; 0: no coefficients
  double referenceArea = 1;      ///< A [m^2]
  fluid::Vec3 dragDirection{1, 0, 0};
  fluid::Vec3 liftDirection{0, 1, 0};
};

/// \brief p(from) - p(to): on a patch (boundary values of the two nearest faces) or, without a
/// patch, at the cells whose centroids are nearest.
struct PressureDifferenceReport {
  std::string name;
  fluid::Vec3 from{0, 0, 0}, to{0, 0, 0};
  std::string patch;  ///< "" for cell values
};

/// \brief Pressure of the cell nearest to a point (of the reference mesh), written every step.
struct ProbeReport {
  std::string name;
  fluid::Vec3 point{0, 0, 0};
};

/// \brief Lid-driven cavity comparison with Ghia et al. (1982).
struct GhiaReport {
  bool enabled = false;
  int re = 100;
  double lidSpeed = 1;
};

/// \brief What a run reports from the fluid solution besides the solver's own numbers.
struct FluidReports {
  std::vector<ForceReport> forces;
  std::vector<PressureDifferenceReport> pressureDifferences;
  std::vector<ProbeReport> probes;
  std::vector<std::string> flows;  ///< patches whose flow rate and mean pressure are written
  bool meanPressure = false;       ///< the volume-weighted mean pressure written every step
  GhiaReport ghia;
};

/// Reports requested by a view of the `fluid` section; `options` are the ones read from it (the
/// Ghia check verifies the scene's Reynolds number against the table's).
FluidReports readFluidReports(const SceneConfig& fluidSection, const HexMesh& mesh, const fluid::FluidOptions& options);

}  // namespace mfsi
