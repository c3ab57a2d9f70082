#include "fluid/FluidConfig.hpp"

#include "core/Suggest.hpp"
#include "fluid/GhiaTable.hpp"

#include <cmath>

namespace mfsi {

using namespace fluid;

Schema timeFunctionSchema(const std::string& what) {
  return Schema::map(what)
      .key("type",
           Schema::choice("constant: 1; oneMinusCos: 1 - cos(2 pi t / period); cosineRamp: (1 - cos(pi t "
                          "/ period)) / 2 up to t = period, then 1; halfPowerSine: sin(pi tau / "
                          "pulseDuration)^exponent for tau = t mod period < pulseDuration, else 0",
                          {"constant", "oneMinusCos", "cosineRamp", "halfPowerSine"}),
           Default("constant"))
      .key("period", Schema::real("period or ramp time", "s").greaterThan(0), Default(1.0))
      .key("pulseDuration", Schema::real("halfPowerSine: pulse length (0: period / 2)", "s").atLeast(0), Default(0.0))
      .key("exponent", Schema::real("halfPowerSine: exponent", "-").greaterThan(0), Default(0.5))
      .key("secondAmplitude",
           Schema::real("halfPowerSine: a second pulse right after the first, this times the boundary value "
                        "(negative: the other way; 0: none)",
                        "-"),
           Default(0.0))
      .key("secondDuration", Schema::real("halfPowerSine: the second pulse's length", "s").atLeast(0), Default(0.0));
}

fluid::TimeFunction readTimeFunction(const SceneConfig& f) {
  using fluid::TimeFunction;
  TimeFunction tf;
  const std::string type = f.get<std::string>("type");
  tf.kind = type == "oneMinusCos"     ? TimeFunction::Kind::OneMinusCos
            : type == "cosineRamp"    ? TimeFunction::Kind::CosineRamp
            : type == "halfPowerSine" ? TimeFunction::Kind::HalfPowerSine
                                      : TimeFunction::Kind::Constant;
  tf.period = f.get<double>("period");
  tf.pulseDuration = f.get<double>("pulseDuration");
  tf.exponent = f.get<double>("exponent");
  tf.secondAmplitude = f.get<double>("secondAmplitude");
  tf.secondDuration = f.get<double>("secondDuration");
  if (tf.pulseDuration > tf.period) throw InputError(f.where("pulseDuration"), "must not exceed the period");
  const double first = tf.pulseDuration > 0 ? tf.pulseDuration : 0.5 * tf.period;
  if (tf.secondAmplitude != 0 && !(tf.secondDuration > 0))
    throw InputError(f.where("secondDuration"), "a second pulse (secondAmplitude) needs a duration > 0");
  if (tf.secondAmplitude != 0 && first + tf.secondDuration > tf.period * (1 + 1e-12))
    throw InputError(f.where("secondDuration"), "the two pulses (" + std::to_string(first) + " + " +
                                                    std::to_string(tf.secondDuration) + " s) must fit in the period (" +
                                                    std::to_string(tf.period) + " s)");
  return tf;
}

namespace {

const std::vector<std::string> kBoundaryTypes = {
    "fixedVelocity", "flowRate", "wall", "movingWall", "membraneWall", "slip", "empty", "fixedPressure", "resistance"};

Schema linearSolverSchema(const std::string& what, double tolerance, int maxIter) {
  return Schema::map(what +
                     " linear solver: stops at scaled residual < tolerance, residual reduced by relTol, or maxIter")
      .key("tolerance", Schema::real("absolute tolerance on the scaled residual", "-").atLeast(0), Default(tolerance))
      .key("relTol", Schema::real("relative reduction of the residual (0: off)", "-").atLeast(0).lessThan(1),
           Default(0.0))
      .key("maxIter", Schema::integer("iteration limit per solve").atLeast(1), Default(maxIter));
}

Schema boundarySchema() {
  return Schema::map("boundary condition of a patch (or of both sides of a baffle)")
      .key("type",
           Schema::choice("fixedVelocity: prescribed velocity; flowRate: volumetric inflow along the inward normal; "
                          "wall: no-slip, tangential velocity `velocity` (a driven lid); movingWall: no-slip moving "
                          "with the mesh; membraneWall: no-slip moving with the coupled membrane on it; slip: free "
                          "slip / symmetry; empty: front/back of a one-cell-thick 2D mesh; "
                          "fixedPressure: p prescribed, zero-gradient velocity (outflow); resistance: p = resistance * "
                          "q + pressure, q the outflow rate",
                          kBoundaryTypes))
      .key("velocity",
           Schema::realVector(3, "fixedVelocity: value (peak of a parabolic profile); wall: wall velocity", "m/s"),
           Default(std::array<double, 3>{0, 0, 0}))
      .key("flowRate", Schema::real("flowRate: volumetric inflow, positive into the domain", "m^3/s"), Default(0.0))
      .key("pressure", Schema::real("fixedPressure: p; resistance: p0", "Pa"), Default(0.0))
      .key("resistance", Schema::real("resistance: C_r", "Pa s/m^3").atLeast(0), Default(0.0))
      .key("valve",
           Schema::map("fixedPressure/resistance: a valve, open (the pressure condition) while openFrom <= t mod "
                       "period < openTo and a closed no-slip wall otherwise")
               .key("period", Schema::real("the valve's cycle", "s").greaterThan(0))
               .key("openFrom", Schema::real("opens at this time of the cycle", "s").atLeast(0), Default(0.0))
               .key("openTo", Schema::real("closes at this time of the cycle", "s").greaterThan(0)),
           Presence::OptionalSection)
      .key("profile",
           Schema::choice("fixedVelocity/flowRate: shape across the patch, s in [0, 1] across the extent along "
                          "each of parabolicAxes; parabolic = prod 4 s (1 - s); linear = prod s",
                          {"uniform", "parabolic", "linear"}),
           Default("uniform"))
      .key("parabolicAxes",
           Schema::list("parabolic: axes the profile varies across", Schema::choice("axis", {"x", "y", "z"})),
           Presence::Optional)
      .key("parabolicMin",
           Schema::realVector(3, "parabolic: lower end of the extent per axis (min >= max: patch box)", "m"),
           Default(std::array<double, 3>{0, 0, 0}))
      .key("parabolicMax", Schema::realVector(3, "parabolic: upper end of the extent per axis", "m"),
           Default(std::array<double, 3>{0, 0, 0}))
      .key("timeFunction", timeFunctionSchema("factor f(t) on the velocity, flow rate or pressure"),
           Presence::Optional);
}

Schema forceSchema() {
  return Schema::map("force and moment on a patch (or both sides of a baffle), metrics fluid.<patch>.*")
      .key("patch", Schema::string("patch or baffle name"))
      .key("point", Schema::realVector(3, "moment reference point", "m"), Default(std::array<double, 3>{0, 0, 0}))
      .key("referenceVelocity",
           Schema::real("U of the coefficients c = 2 F.e / (rho U^2 A) (0: no coefficients)", "m/s").atLeast(0),
           Default(0.0))
      .key("referenceArea", Schema::real("A of the coefficients", "m^2").greaterThan(0), Default(1.0))
      .key("dragDirection", Schema::realVector(3, "direction e of c_D", "-"), Default(std::array<double, 3>{1, 0, 0}))
      .key("liftDirection", Schema::realVector(3, "direction e of c_L", "-"), Default(std::array<double, 3>{0, 1, 0}));
}

Schema pressureDifferenceSchema() {
  return Schema::map("pressure difference p(from) - p(to), metric fluid.<name>")
      .key("name", Schema::string("metric name"))
      .key("from", Schema::realVector(3, "first point", "m"))
      .key("to", Schema::realVector(3, "second point", "m"))
      .key("patch", Schema::string("take boundary values on this patch ('': nearest cell values)"), Default(""));
}

Vec3 vec3(const SceneConfig& c, const std::string& key) { return c.get<std::array<double, 3>>(key); }

// Names a boundary entry may use: patches, and baffles (both sides at once).
std::vector<std::string> boundaryNames(const HexMesh& mesh) {
  std::vector<std::string> names;
  for (const auto& p : mesh.patches()) {
    names.push_back(p.name);
    const std::string suffix = "_master";
    if (p.kind == PatchKind::BaffleMaster && p.name.size() > suffix.size())
      names.push_back(p.name.substr(0, p.name.size() - suffix.size()));
  }
  return names;
}

void checkBoundaryName(const SceneConfig& c, const std::string& key, const std::string& name, const HexMesh& mesh) {
  const auto names = boundaryNames(mesh);
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw InputError(c.where(key), "the mesh has no patch or baffle named '" + name + "'" + didYouMean(name, names) +
                                       "; patches: " + joinList(names));
}

PatchBC readBoundary(const SceneConfig& b) {
  PatchBC bc;
  const std::string type = b.get<std::string>("type");
  if (type == "fixedVelocity") bc.type = BoundaryType::FixedVelocity;
  if (type == "flowRate") bc.type = BoundaryType::FlowRate;
  if (type == "wall" || type == "movingWall" || type == "membraneWall") bc.type = BoundaryType::Wall;
  if (type == "movingWall") bc.wallMotion = WallMotion::MeshVelocity;
  if (type == "membraneWall") bc.wallMotion = WallMotion::External;  // velocity from the coupled membrane
  if (type == "slip") bc.type = BoundaryType::Slip;
  if (type == "empty") bc.type = BoundaryType::Empty;
  if (type == "fixedPressure") bc.type = BoundaryType::FixedPressure;
  if (type == "resistance") bc.type = BoundaryType::Resistance;
  bc.velocity = vec3(b, "velocity");
  bc.flowRate = b.get<double>("flowRate");
  bc.pressure = b.get<double>("pressure");
  bc.resistance = b.get<double>("resistance");
  const std::string profile = b.get<std::string>("profile");
  bc.profile = profile == "parabolic" ? Profile::Parabolic : profile == "linear" ? Profile::Linear : Profile::Uniform;
  const auto axes = b.get<std::vector<std::string>>("parabolicAxes");
  for (const auto& a : axes) bc.parabolicAxes[a[0] - 'x'] = true;
  const bool shaped = bc.profile == Profile::Parabolic || bc.profile == Profile::Linear;
  if (shaped && axes.empty())
    throw InputError(b.where("profile"), "a " + profile + " profile needs 'parabolicAxes' (e.g. [y])");
  if (shaped && bc.type != BoundaryType::FixedVelocity && bc.type != BoundaryType::FlowRate)
    throw InputError(b.where("profile"),
                     "a " + profile + " profile applies to fixedVelocity and flowRate patches only");
  bc.parabolicMin = vec3(b, "parabolicMin");
  bc.parabolicMax = vec3(b, "parabolicMax");
  if (b.has("valve")) {
    if (bc.type != BoundaryType::FixedPressure && bc.type != BoundaryType::Resistance)
      throw InputError(b.where("valve"), "a valve applies to fixedPressure and resistance patches only");
    bc.valve.period = b.get<double>("valve.period");
    bc.valve.openFrom = b.get<double>("valve.openFrom");
    bc.valve.openTo = b.get<double>("valve.openTo");
    if (!(bc.valve.openFrom < bc.valve.openTo && bc.valve.openTo <= bc.valve.period))
      throw InputError(b.where("valve"), "needs 0 <= openFrom < openTo <= period, got " +
                                             std::to_string(bc.valve.openFrom) + ", " +
                                             std::to_string(bc.valve.openTo) + ", " + std::to_string(bc.valve.period));
  }
  if (b.has("timeFunction")) bc.timeFunction = readTimeFunction(b.child("timeFunction"));
  return bc;
}

}  // namespace

Schema fluidSchema() {
  const FluidOptions d;  // defaults below mirror these
  Schema pimple =
      Schema::map("pressure-velocity coupling: PIMPLE per time step; SIMPLE iterations when steady")
          .key("outerCorrectors",
               Schema::integer("outer iterations per step (SIMPLE iterations per step when steady)").atLeast(1),
               Default(d.pimple.nOuterCorrectors))
          .key("correctors", Schema::integer("pressure correctors per outer iteration (PISO)").atLeast(1),
               Default(d.pimple.nCorrectors))
          .key("nonOrthogonalCorrectors",
               Schema::integer("extra pressure solves for the non-orthogonal correction").atLeast(0),
               Default(d.pimple.nNonOrthogonalCorrectors))
          .key("momentumPredictor", Schema::boolean("solve the momentum equation before the pressure correctors"),
               Default(d.pimple.momentumPredictor))
          .key("outerTolerance",
               Schema::real("stop the outer loop when the initial momentum and pressure residuals drop below (0: off)",
                            "-")
                   .atLeast(0),
               Default(d.pimple.outerTolerance))
          .key("relaxVelocity",
               Schema::real("implicit under-relaxation of momentum (~0.7-0.9 when steady)", "-")
                   .greaterThan(0)
                   .atMost(1),
               Default(d.pimple.relaxVelocity))
          .key("relaxPressure",
               Schema::real("explicit under-relaxation of pressure (~0.2-0.3 when steady)", "-")
                   .greaterThan(0)
                   .atMost(1),
               Default(d.pimple.relaxPressure))
          .key("consistent",
               Schema::boolean("SIMPLEC (steady only): the pressure equation with rAtU = V / (a_P - H1); pressure "
                               "then needs no under-relaxation (relaxPressure: 1), relaxVelocity < 1"),
               Default(d.pimple.consistent))
          .key("ddtCorrection", Schema::boolean("Rhie-Chow correction of the time-derivative term"),
               Default(d.pimple.ddtCorrection))
          .key("extrapolateGuess",
               Schema::boolean("start the first momentum solve of a step from U extrapolated in time, and the final "
                               "pressure solve from the last step's final-corrector change (initial guesses only)"),
               Default(d.pimple.extrapolateGuess));
  Schema pressure = linearSolverSchema("pressure", d.pressureSolver.tolerance, d.pressureSolver.maxIter);
  pressure
      .key("finalRelTol",
           Schema::real("relTol of the last pressure solve of a step (pFinal; < 0: relTol)", "-").lessThan(1),
           Default(d.pressureFinalRelTol))
      .key("finestSweeps",
           Schema::integer("AMG smoother applications on the finest level in the pressure solves before the final one "
                           "of a step (the final one uses 1)")
               .atLeast(1),
           Default(d.pressureFinestSweeps))
      .key("preconditioner", Schema::choice("conjugate-gradient preconditioner", {"amg", "jacobi"}), Default("amg"))
      .key("overlapHalo",
           Schema::boolean("on several ranks, run each halo exchange of the pressure solve while its product "
                           "multiplies the rows that read no ghost (the same results; off: exchange first; overlap "
                           "gains nothing on one shared-memory node)"),
           Default(d.overlapHalo))
      .key("preconditionerRefresh",
           Schema::integer("most outer iterations between AMG value refreshes (earlier when the final pressure solve "
                           "needs 25 % more iterations than after the last refresh)")
               .atLeast(1),
           Default(d.pressurePreconditionerRefresh));
  Schema solvers =
      Schema::map("linear solvers")
          .key("pressure", pressure, Presence::Optional)
          .key("momentum", linearSolverSchema("momentum", d.momentumSolver.tolerance, d.momentumSolver.maxIter),
               Presence::Optional);
  return Schema::map("incompressible Navier-Stokes on the scene mesh (finite volumes, PIMPLE/SIMPLE)")
      .key("density", Schema::real("density rho", "kg/m^3").greaterThan(0), Default(d.density))
      .key("viscosity", Schema::real("dynamic viscosity mu (give this or nu)", "Pa s").greaterThan(0),
           Presence::OptionalSection)
      .key("nu", Schema::real("kinematic viscosity nu = mu / rho (give this or viscosity)", "m^2/s").greaterThan(0),
           Presence::OptionalSection)
      .key("regions",
           Schema::list("other fluids: each in the cells its patch reaches without crossing a baffle (e.g. the air "
                        "chamber behind a membrane with blood on its other side); the rest keep density and "
                        "viscosity",
                        Schema::map("a fluid region")
                            .key("patch", Schema::string("a patch of the region (every region it touches)"))
                            .key("density", Schema::real("density rho", "kg/m^3").greaterThan(0))
                            .key("viscosity", Schema::real("dynamic viscosity mu", "Pa s").greaterThan(0))),
           Presence::Optional)
      .key("bodyForce", Schema::realVector(3, "body acceleration g", "m/s^2"), Default(std::array<double, 3>{0, 0, 0}))
      .key("artificialSoundSpeed",
           Schema::real("artificial compressibility: (1/(rho c^2)) dp/dt + div u = 0; 0 = incompressible", "m/s")
               .atLeast(0),
           Default(d.artificialCompressibility.soundSpeed))
      .key("divergenceVelocityFactor",
           Schema::real("runaway-growth guard: the run stops as diverged when max |U| over the cells exceeds this "
                        "factor times the velocity scale of the scene, checked once per step (0: off). The scale is "
                        "the largest of: the prescribed boundary velocities at the peak of their time functions "
                        "(fixedVelocity, wall velocities, flowRate / patch area times the profile's peak-to-mean "
                        "ratio), |initial.velocity|, sqrt(2 dp / rho) for the range dp of the prescribed and initial "
                        "pressures, sqrt(2 |g| L) for the body force and the mesh's bounding-box diagonal L, and the "
                        "largest velocity of a moving wall, membrane or mesh boundary seen so far in the run",
                        "-")
               .atLeast(0),
           Default(d.divergenceVelocityFactor))
      .key("means",
           Schema::map("running time means of U and p, cell fields UMean and pMean of the field output, weighted by "
                       "the time step as OpenFOAM's fieldAverage: mean = (1 - dt/T) mean + (dt/T) field, T the time "
                       "averaged so far (zero until the first step that enters)")
               .key("start", Schema::real("steps that end at or after this time enter the means", "s"),
                    Default(d.means.start)),
           Presence::OptionalSection)
      .key("timeScheme",
           Schema::choice("steady: SIMPLE; euler: implicit Euler; bdf2: second-order backward differences",
                          {"steady", "euler", "bdf2"}),
           Default("bdf2"))
      .key("convection",
           Schema::choice("face interpolation of the convected velocity",
                          {"upwind", "linear", "limitedLinear", "vanLeer"}),
           Default("linear"))
      .key("gradient", Schema::choice("cell gradients", {"gaussLinear", "leastSquares"}), Default("gaussLinear"))
      .key("nonOrthogonalLimit",
           Schema::real("OpenFOAM's 'limited psi' face-normal gradients: each face's explicit non-orthogonal "
                        "correction (pressure and viscous terms) is at most psi / (1 - psi) times its orthogonal "
                        "part; 1 = corrected, 0 = uncorrected, 0.5 = OpenFOAM's usual choice for distorted meshes",
                        "-")
               .atLeast(0)
               .atMost(1),
           Default(d.nonOrthogonalLimit))
      .key("pimple", pimple, Presence::Optional)
      .key("solvers", solvers, Presence::Optional)
      .key("initial",
           Schema::map("initial fields")
               .key("velocity", Schema::realVector(3, "uniform initial velocity", "m/s"),
                    Default(std::array<double, 3>{0, 0, 0}))
               .key("pressure", Schema::real("uniform initial pressure", "Pa"), Default(0.0)),
           Presence::Optional)
      .key("boundary",
           Schema::freeMap("condition per patch name; wall, symmetry, empty and baffle patches may be omitted "
                           "(wall -> wall, symmetry -> slip, empty -> empty, baffle -> wall moved by a membrane)",
                           boundarySchema()),
           Presence::Optional)
      .key("forces",
           Schema::list("patches whose force and moment are reported: every step in steps.csv (fluid.<patch>.force_x "
                        "... moment_z, c_D and c_L) and at the end in summary.json",
                        forceSchema()),
           Presence::Optional)
      .key("pressureDifferences",
           Schema::list("pressure differences reported every step in steps.csv (fluid.<name>) and at the end in "
                        "summary.json",
                        pressureDifferenceSchema()),
           Presence::Optional)
      .key("probes",
           Schema::list("probes written every step (steps.csv columns fluid.probe.<name> for p, and "
                        "fluid.probe.<name>.Ux, .Uy, .Uz): the values of the cell "
                        "whose centroid is nearest to the point in the mesh as built (the cell moves with a moving "
                        "mesh)",
                        Schema::map("a probe")
                            .key("name", Schema::string("column name"))
                            .key("point", Schema::realVector(3, "point", "m"))),
           Presence::Optional)
      .key("flows",
           Schema::list("patches whose flow is written every step (steps.csv columns fluid.<patch>.flowRate, the "
                        "volumetric flow out of the fluid, and fluid.<patch>.pressure, the area-weighted mean of "
                        "its boundary pressure)",
                        Schema::string("patch name")),
           Presence::Optional)
      .key("meanPressure",
           Schema::boolean("write the volume-weighted mean pressure every step (steps.csv column "
                           "fluid.meanPressure; with regions, that of the cells no region names and "
                           "fluid.meanPressure.<patch> each region's)"),
           Default(false))
      .key("ghia",
           Schema::map("compare a lid-driven cavity (mesh bounding box in x, y; lid at y max moving in +x) with "
                       "Ghia, Ghia & Shin (1982): metrics fluid.ghia_u_max_err, fluid.ghia_v_max_err")
               .key("enabled", Schema::boolean("compute the comparison (false: skip, e.g. at another Re)"),
                    Default(true))
               .key("re", Schema::choice("Reynolds number of the table; must equal rho U L / mu of the scene", {"100"}),
                    Default("100"))
               .key("lidSpeed", Schema::real("lid speed U", "m/s").greaterThan(0), Default(1.0)),
           Presence::OptionalSection);
}

FluidOptions readFluidOptions(const SceneConfig& c, const HexMesh& mesh) {
  FluidOptions o;
  o.density = c.get<double>("density");
  const bool hasMu = c.has("viscosity"), hasNu = c.has("nu");
  if (hasMu == hasNu)
    throw InputError(c.where(hasMu ? "nu" : ""), hasMu
                                                     ? "give either 'viscosity' (dynamic) or 'nu' (kinematic), not both"
                                                     : "give the viscosity: 'viscosity' (dynamic, Pa s) or 'nu' "
                                                       "(kinematic, m^2/s)");
  o.viscosity = hasMu ? c.get<double>("viscosity") : c.get<double>("nu") * o.density;
  o.bodyForce = vec3(c, "bodyForce");
  o.artificialCompressibility.soundSpeed = c.get<double>("artificialSoundSpeed");
  for (std::size_t i = 0; i < c.size("regions"); ++i) {
    const SceneConfig r = c.child("regions." + std::to_string(i));
    FluidRegion fr{r.get<std::string>("patch"), r.get<double>("density"), r.get<double>("viscosity")};
    if (mesh.findPatch(fr.patch) < 0) throw InputError(r.where("patch"), mesh.noPatchMessage(fr.patch));
    for (const FluidRegion& other : o.regions)
      if (other.patch == fr.patch) throw InputError(r.where("patch"), "a second region for patch '" + fr.patch + "'");
    if (o.artificialCompressibility.soundSpeed > 0)
      throw InputError(r.where("patch"), "fluid regions with artificial compressibility (artificialSoundSpeed) are "
                                         "not supported yet");
    o.regions.push_back(fr);
  }
  const std::string ts = c.get<std::string>("timeScheme");
  o.timeScheme = ts == "steady" ? TimeScheme::Steady : ts == "euler" ? TimeScheme::Euler : TimeScheme::BDF2;
  const std::string cs = c.get<std::string>("convection");
  o.convection = cs == "upwind"          ? ConvectionScheme::Upwind
                 : cs == "limitedLinear" ? ConvectionScheme::LimitedLinear
                 : cs == "vanLeer"       ? ConvectionScheme::VanLeer
                                         : ConvectionScheme::Linear;
  o.gradient =
      c.get<std::string>("gradient") == "leastSquares" ? GradientScheme::LeastSquares : GradientScheme::GaussLinear;
  o.nonOrthogonalLimit = c.get<double>("nonOrthogonalLimit");

  o.pimple.nOuterCorrectors = c.get<int>("pimple.outerCorrectors");
  o.pimple.nCorrectors = c.get<int>("pimple.correctors");
  o.pimple.nNonOrthogonalCorrectors = c.get<int>("pimple.nonOrthogonalCorrectors");
  o.pimple.momentumPredictor = c.get<bool>("pimple.momentumPredictor");
  o.pimple.outerTolerance = c.get<double>("pimple.outerTolerance");
  o.pimple.relaxVelocity = c.get<double>("pimple.relaxVelocity");
  o.pimple.relaxPressure = c.get<double>("pimple.relaxPressure");
  o.pimple.consistent = c.get<bool>("pimple.consistent");
  if (o.pimple.consistent && o.timeScheme != TimeScheme::Steady)
    throw InputError(c.where("pimple.consistent"), "SIMPLEC (consistent: true) needs timeScheme: steady");
  if (o.pimple.consistent && o.pimple.relaxVelocity >= 1.0)
    throw InputError(c.where("pimple.consistent"),
                     "SIMPLEC (consistent: true) needs relaxVelocity < 1 (0.9 is usual): with 1 its a_P - H1 is the "
                     "continuity error of the face fluxes, not a coefficient");
  o.pimple.ddtCorrection = c.get<bool>("pimple.ddtCorrection");
  o.pimple.extrapolateGuess = c.get<bool>("pimple.extrapolateGuess");

  auto solver = [&](const std::string& k) {
    return LinearSolverOptions{c.get<double>(k + ".tolerance"), c.get<double>(k + ".relTol"),
                               c.get<int>(k + ".maxIter")};
  };
  o.pressureSolver = solver("solvers.pressure");
  o.momentumSolver = solver("solvers.momentum");
  o.pressureFinalRelTol = c.get<double>("solvers.pressure.finalRelTol");
  o.pressureFinestSweeps = c.get<int>("solvers.pressure.finestSweeps");
  o.pressurePreconditioner = c.get<std::string>("solvers.pressure.preconditioner") == "jacobi"
                                 ? PressurePreconditioner::Jacobi
                                 : PressurePreconditioner::Amg;
  o.pressurePreconditionerRefresh = c.get<int>("solvers.pressure.preconditionerRefresh");
  o.overlapHalo = c.get<bool>("solvers.pressure.overlapHalo");
  o.divergenceVelocityFactor = c.get<double>("divergenceVelocityFactor");
  o.means.enabled = c.has("means");
  if (o.means.enabled) o.means.start = c.get<double>("means.start");
  o.initialVelocity = vec3(c, "initial.velocity");
  o.initialPressure = c.get<double>("initial.pressure");

  for (const auto& name : c.keys("boundary")) {
    checkBoundaryName(c, "boundary." + name, name, mesh);
    o.boundaries[name] = readBoundary(c.child("boundary." + name));
  }
  // Plain patches have no natural condition: name the missing key here rather than in the solver.
  for (const auto& p : mesh.patches())
    if (p.kind == PatchKind::Patch && !o.boundaries.count(p.name))
      throw InputError(c.where("boundary"), "patch '" + p.name + "' needs a condition (key fluid.boundary." + p.name +
                                                "; its mesh patch kind is 'patch', not wall/symmetry/empty)");
  return o;
}

FluidReports readFluidReports(const SceneConfig& c, const HexMesh& mesh, const FluidOptions& options) {
  FluidReports r;
  for (std::size_t i = 0; i < c.size("forces"); ++i) {
    const SceneConfig f = c.child("forces." + std::to_string(i));
    ForceReport fr;
    fr.patch = f.get<std::string>("patch");
    checkBoundaryName(f, "patch", fr.patch, mesh);
    fr.point = vec3(f, "point");
    fr.referenceVelocity = f.get<double>("referenceVelocity");
    fr.referenceArea = f.get<double>("referenceArea");
    fr.dragDirection = vec3(f, "dragDirection");
    fr.liftDirection = vec3(f, "liftDirection");
    for (Vec3* e : {&fr.dragDirection, &fr.liftDirection}) {
      const double n = std::sqrt((*e)[0] * (*e)[0] + (*e)[1] * (*e)[1] + (*e)[2] * (*e)[2]);
      if (!(n > 0))
        throw InputError(f.where(e == &fr.dragDirection ? "dragDirection" : "liftDirection"), "must be non-zero");
      for (auto& x : *e) x /= n;
    }
    r.forces.push_back(fr);
  }
  for (std::size_t i = 0; i < c.size("pressureDifferences"); ++i) {
    const SceneConfig p = c.child("pressureDifferences." + std::to_string(i));
    PressureDifferenceReport pr;
    pr.name = p.get<std::string>("name");
    pr.from = vec3(p, "from");
    pr.to = vec3(p, "to");
    pr.patch = p.get<std::string>("patch");
    if (!pr.patch.empty() && mesh.findPatch(pr.patch) < 0)
      throw InputError(p.where("patch"), mesh.noPatchMessage(pr.patch));
    r.pressureDifferences.push_back(pr);
  }
  for (std::size_t i = 0; i < c.size("probes"); ++i) {
    const SceneConfig p = c.child("probes." + std::to_string(i));
    r.probes.push_back({p.get<std::string>("name"), vec3(p, "point")});
  }
  for (std::size_t i = 0; i < c.size("flows"); ++i) {
    const std::string key = "flows." + std::to_string(i), patch = c.get<std::string>(key);
    if (mesh.findPatch(patch) < 0) throw InputError(c.where(key), mesh.noPatchMessage(patch));
    r.flows.push_back(patch);
  }
  r.meanPressure = c.get<bool>("meanPressure");
  if (c.has("ghia") && c.get<bool>("ghia.enabled")) {
    r.ghia.enabled = true;
    r.ghia.re = std::stoi(c.get<std::string>("ghia.re"));
    r.ghia.lidSpeed = c.get<double>("ghia.lidSpeed");
    // Cavity width from the mesh: Re = rho U L / mu must be the table's.
    auto P = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
    double lo = 1e300, hi = -1e300;
    for (int n = 0; n < static_cast<int>(P.extent(0)); ++n) {
      lo = std::min(lo, P(n, 0));
      hi = std::max(hi, P(n, 0));
    }
    const double re = options.density * r.ghia.lidSpeed * (hi - lo) / options.viscosity;
    if (std::abs(re / r.ghia.re - 1) > 1e-3)
      throw InputError(c.where("ghia"), "the scene's Reynolds number rho U L / mu = " + formatReal(re) +
                                            " differs from the table's " + std::to_string(r.ghia.re) +
                                            " (set fluid.ghia.enabled=false to run without the comparison)");
  }
  return r;
}

}  // namespace mfsi
