#include "coupling/orchestrator/CouplingConfig.hpp"

#include "fluid/FluidConfig.hpp"

#include <algorithm>

namespace mfsi {

Schema couplingSchema() {
  const CouplingOptions o;
  const coupling::AccelerationOptions& a = o.acceleration;
  Schema motion =
      Schema::map("interior mesh motion: the point-Laplacian of the boundary displacement, swept or solved")
          .key("method",
               Schema::choice("cg: solved by conjugate gradients to relTol (the default: Jacobi sweeps spread a "
                              "wall motion by ~sqrt(sweeps) cells only); jacobi: `sweeps` Jacobi sweeps per motion "
                              "(the seed's smoother)",
                              {"cg", "jacobi"}),
               Default("cg"))
          .key("sweeps", Schema::integer("jacobi: sweeps per motion").atLeast(0), Default(o.motion.sweeps))
          .key("relTol", Schema::real("cg: residual per motion, relative to the larger of the warm start's residual and the displacement field's scale", "-").greaterThan(0).lessThan(1),
               Default(o.motion.relTol))
          .key("maxIterations", Schema::integer("cg: iterations per motion").atLeast(1),
               Default(o.motion.maxIterations))
          .key("preconditioner",
               Schema::choice("cg: jacobi (the diagonal: many cheap iterations) or amg (smoothed-aggregation "
                              "multigrid, set up once on the reference mesh: a few iterations at any size)",
                              {"jacobi", "amg"}),
               Default("amg"))
          .key("minScaledJacobian",
               Schema::real("quality guard: below this the motion is retried (more sweeps, then the stiffened "
                            "smoother); an inverted cell stops the run",
                            "-")
                   .atLeast(0)
                   .atMost(1),
               Default(o.motion.minScaledJacobian))
          .key("retries", Schema::integer("jacobi: retries of the quality guard").atLeast(0), Default(o.motion.retries))
          .key("distanceExponent",
               Schema::real("cg: edge stiffness times 1 / d^q, d the reference distance from the edge to the nearest "
                            "membrane or body node (cells near the moving surfaces move more rigidly with them, the "
                            "far ones deform); 0: off",
                            "-")
                   .atLeast(0)
                   .atMost(4),
               Default(o.motion.distanceExponent))
          .key("columns",
               Schema::boolean("on a mesh extruded from a membrane patch (layers of cells between it and a wall): "
                               "the nodes of each line of cell edges from a membrane node to the wall move with that "
                               "node, by a factor falling linearly from 1 to 0 along the line, so every layer of the "
                               "column compresses alike; the other nodes are solved as before"),
               Default(false))
          .key("slidingPatches",
               Schema::list("patches whose nodes slide along them (flat walls next to a membrane)",
                            Schema::string("patch name")),
               Presence::Optional)
          .key("bodies",
               Schema::freeMap(
                   "distance-weighted rigid motion of the mesh around coupled bodies (the seed's section 3.2): body "
                   "name (one of bodyPatches) -> its distances; nodes within innerDistance of the body's patches "
                   "move rigidly with it, beyond outerDistance not at all, in between by a cosine blend of its "
                   "motion (rotation angle and translation scaled alike); the Laplacian smooths what is left",
                   Schema::map("the body's reach")
                       .key("innerDistance", Schema::real("distance within which the mesh moves rigidly", "m").atLeast(0))
                       .key("outerDistance",
                            Schema::real("distance beyond which the mesh does not follow the body", "m").atLeast(0))),
               Presence::Optional);
  return Schema::map("two-way fluid-structure coupling of the fluid and the membranes cut from its mesh")
      .key("scheme",
           Schema::choice("implicit: Gauss-Seidel iterations per step (structure first) to fsiTol; explicit: one "
                          "staggered pass per step",
                          {"implicit", "explicit"}),
           Default("implicit"))
      .key("convergence",
           Schema::choice("residuals that must fall below fsiTol: displacement, or both (and the load change)",
                          {"displacement", "both"}),
           Default("both"))
      .key("fsiTol", Schema::real("relative interface residual tolerance", "-").greaterThan(0), Default(o.fsiTol))
      .key("minFsiIter", Schema::integer("fluid solves per step, at least").atLeast(1), Default(o.minFsiIter))
      .key("maxFsiIter", Schema::integer("fluid solves per step, at most").atLeast(1), Default(o.maxFsiIter))
      .key("maxUnconvergedSteps",
           Schema::integer("steps in a row that may end at maxFsiIter before the run stops as diverged").atLeast(1),
           Default(o.maxUnconvergedSteps))
      .key("relaxation",
           Schema::choice("displacement relaxation when iqnMaxCols = 0: aitken (Delta^2) or constant (omegaInit)",
                          {"aitken", "constant"}),
           Default("aitken"))
      .key("omegaInit", Schema::real("first relaxation factor of a step (constant: every iteration)", "-")
                            .greaterThan(0)
                            .atMost(1),
           Default(a.omegaInit))
      .key("omegaMin", Schema::real("Aitken's lower bound on omega", "-").greaterThan(0).atMost(1),
           Default(a.omegaMin))
      .key("iqnMaxCols", Schema::integer("IQN-ILS history columns (> 0 selects IQN-ILS)").atLeast(0),
           Default(a.iqnMaxCols))
      .key("iqnReuseCols", Schema::integer("past time steps whose IQN-ILS columns are reused").atLeast(0),
           Default(a.iqnReuseCols))
      .key("iqnJacobian",
           Schema::choice("the inverse Jacobian of the quasi-Newton method: leastSquares (IQN-ILS, from the history "
                          "alone) or multiVector (IQN-IMVJ: the previous steps' Jacobian updated by this step's "
                          "history, kept in low-rank form; one rank)",
                          {"leastSquares", "multiVector"}),
           Default("leastSquares"))
      .key("iqnJacobianRank",
           Schema::integer("multiVector: the most columns of the carried inverse Jacobian's low-rank part (past it a "
                           "truncated SVD keeps its largest half)")
               .atLeast(2),
           Default(a.iqnJacobianRank))
      .key("iqnFilter",
           Schema::real("QR2 filter: drop a column whose new part is below this fraction of its norm", "-")
               .atLeast(0)
               .lessThan(1),
           Default(a.iqnFilterEps))
      .key("iqnMaxUpdate",
           Schema::real("step-size limiter: a quasi-Newton update larger than this falls back to Aitken (0: off)",
                        "m")
               .atLeast(0),
           Default(a.maxUpdate))
      .key("stallIterations",
           Schema::integer("restart the history after this many iterations without a new smallest residual (0: off)")
               .atLeast(0),
           Default(a.stallIterations))
      .key("forceOmega", Schema::real("under-relaxation of the membrane load between iterations", "-")
                             .greaterThan(0)
                             .atMost(1),
           Default(o.forceOmega))
      .key("pNetFilterTau",
           Schema::real("time constant of a low-pass (IIR) filter on the membrane load; its state advances once per "
                        "step (0: off)",
                        "s")
               .atLeast(0),
           Default(o.pNetFilterTau))
      .key("pNetSmoothIter",
           Schema::integer("steps of conservative smoothing of the membrane load over its surface (total force kept)")
               .atLeast(0),
           Default(o.pNetSmoothIter))
      .key("fsiStartTime", Schema::real("structure frozen (mesh fixed) before this time", "s").atLeast(0),
           Default(o.fsiStartTime))
      .key("fsiRampTime", Schema::real("load ramp 0 -> 100 % after fsiStartTime (0: none)", "s").atLeast(0),
           Default(o.fsiRampTime))
      .key("pClamp", Schema::real("limit on |pNet| of the membrane load (0: none)", "Pa").atLeast(0),
           Default(o.pClamp))
      .key("outsidePressure",
           Schema::real("pressure behind a membrane that replaces a boundary patch (its load is p - this)", "Pa"),
           Default(o.outsidePressure))
      .key("interfaceMass",
           Schema::real("artificial added mass on the membranes in each coupling iteration, taken back at "
                        "convergence (the converged answer is the same): about the fluid's density times the "
                        "depth of fluid a membrane moves; stabilises light membranes in dense fluid (0: off; "
                        "implicit scheme only)",
                        "kg/m^2")
               .atLeast(0),
           Default(o.interfaceMass))
      .key("maxMeshVelocity",
           Schema::real("limit of a coupled body's centre-of-mass move per coupling iteration, divided by the time "
                        "step (0: off)",
                        "m/s")
               .atLeast(0),
           Default(o.maxMeshVelocity))
      .key("maxDeltaDispFrac",
           Schema::real("limit of a membrane node's move per coupling iteration, as a fraction of sqrt(membrane "
                        "area) (0: off)",
                        "-")
               .atLeast(0),
           Default(o.maxDeltaDispFrac))
      .key("fluidStart",
           Schema::choice("where each coupling iteration's fluid solve starts: lastIterate (the previous "
                          "iteration's answer, fewer outer iterations) or stepStart (the step's start: the "
                          "fluid's answer depends on the interface alone)",
                          {"lastIterate", "stepStart"}),
           Default("lastIterate"))
      .key("predictor",
           Schema::choice("the load of each step's first structure solve: lastLoad (the fluid's at t_n) or "
                          "extrapolatedLoad (2 p_n - p_n-1, its linear extrapolation to t_n+1)",
                          {"lastLoad", "extrapolatedLoad"}),
           Default("lastLoad"))
      .key("volumeConstraint",
           Schema::boolean("when the fluid is incompressible and no boundary prescribes its pressure (a closed "
                           "chamber), the membrane patch that closes it solves each step with a volume constraint: "
                           "one multiplier, a uniform pressure, makes its swept volume equal the inflow, so the fluid "
                           "always has a consistent answer (a region bounded by several membranes shares one "
                           "multiplier among them; a membrane between two closed regions carries the difference of "
                           "theirs; coupled bodies that bound it or carry its membrane, on one body or blended "
                           "between several, take it too); "
                           "false: plain Dirichlet-Neumann coupling"),
           Default(o.volumeConstraint))
      .key("viscousTraction",
           Schema::boolean("load the membranes with the fluid's viscous traction too (nodal forces), not the "
                           "pressure alone"),
           Default(o.viscousTraction))
      .key("meshMotion", motion, Presence::Optional)
      .key("bodyPatches",
           Schema::freeMap("rigid bodies of the `bodies` section coupled with the fluid: body name -> the fluid "
                           "patches it carries (movingWall patches; their nodes follow the body rigidly, the fluid's "
                           "force and moment on them load the body)",
                           Schema::list("fluid patches of the body", Schema::string("patch name"))),
           Presence::Optional)
      .key("lumpedChamber",
           Schema::map("a gas chamber behind a membrane patch that is not meshed (its inertia negligible, e.g. a "
                       "pump's air chamber): one uniform pressure, the multiplier of a volume constraint on the "
                       "membrane, and a volume that grows by the prescribed inflow (steps.csv: chamberPressure)")
               .key("membrane", Schema::string("the membrane (a boundaryPatch membrane) the chamber lies behind"))
               .key("flowRate", Schema::real("inflow into the chamber, times the time function", "m^3/s"))
               .key("timeFunction", timeFunctionSchema("factor f(t) on the flow rate"), Presence::Optional),
           Presence::OptionalSection)
      .key("parentBodyPatches",
           Schema::freeMap("membranes mounted on coupled bodies: membrane name -> patches of bodyPatches; each "
                           "membrane node follows the body of the nearest listed patch, its FEM displacement (and "
                           "clamp) relative to that body's frame; the membrane's fluid load is passed on to the body",
                           Schema::list("parent patches", Schema::string("patch or baffle name"))),
           Presence::Optional);
}

CouplingOptions readCouplingOptions(const SceneConfig& c) {
  CouplingOptions o;
  o.scheme = c.get<std::string>("scheme") == "explicit" ? CouplingScheme::Explicit : CouplingScheme::Implicit;
  o.convergence = c.get<std::string>("convergence") == "displacement" ? CouplingConvergence::Displacement
                                                                     : CouplingConvergence::Both;
  o.fsiTol = c.get<double>("fsiTol");
  o.minFsiIter = c.get<int>("minFsiIter");
  o.maxFsiIter = c.get<int>("maxFsiIter");
  if (o.minFsiIter > o.maxFsiIter)
    throw InputError(c.where("minFsiIter"), "minFsiIter (" + std::to_string(o.minFsiIter) + ") exceeds maxFsiIter (" +
                                                std::to_string(o.maxFsiIter) + ")");
  o.maxUnconvergedSteps = c.get<int>("maxUnconvergedSteps");
  coupling::AccelerationOptions& a = o.acceleration;
  a.omegaInit = c.get<double>("omegaInit");
  a.omegaMin = c.get<double>("omegaMin");
  a.iqnMaxCols = c.get<int>("iqnMaxCols");
  a.iqnReuseCols = c.get<int>("iqnReuseCols");
  a.iqnJacobian = c.get<std::string>("iqnJacobian") == "multiVector" ? coupling::IqnJacobian::MultiVector
                                                                      : coupling::IqnJacobian::LeastSquares;

  a.iqnJacobianRank = c.get<int>("iqnJacobianRank");
  a.iqnFilterEps = c.get<double>("iqnFilter");
  a.maxUpdate = c.get<double>("iqnMaxUpdate");
  a.stallIterations = c.get<int>("stallIterations");
  a.method = a.iqnMaxCols > 0                                    ? coupling::AccelerationMethod::IqnIls
             : c.get<std::string>("relaxation") == "constant" ? coupling::AccelerationMethod::Constant
                                                              : coupling::AccelerationMethod::Aitken;
  if (a.omegaMin > a.omegaInit && a.method == coupling::AccelerationMethod::Aitken)
    throw InputError(c.where("omegaMin"), "omegaMin exceeds omegaInit");
  o.forceOmega = c.get<double>("forceOmega");
  o.pNetFilterTau = c.get<double>("pNetFilterTau");
  o.pNetSmoothIter = c.get<int>("pNetSmoothIter");
  o.fsiStartTime = c.get<double>("fsiStartTime");
  o.fsiRampTime = c.get<double>("fsiRampTime");
  o.pClamp = c.get<double>("pClamp");
  o.outsidePressure = c.get<double>("outsidePressure");
  o.interfaceMass = c.get<double>("interfaceMass");
  if (o.interfaceMass > 0 && o.scheme == CouplingScheme::Explicit)
    throw InputError(c.where("interfaceMass"),
                     "interfaceMass needs 'scheme: implicit': its term vanishes only when the coupling iteration "
                     "has converged, which the explicit scheme never checks");
  o.viscousTraction = c.get<bool>("viscousTraction");
  o.volumeConstraint = c.get<bool>("volumeConstraint");
  o.fluidFromStepStart = c.get<std::string>("fluidStart") == "stepStart";
  o.extrapolatedPredictor = c.get<std::string>("predictor") == "extrapolatedLoad";
  o.maxMeshVelocity = c.get<double>("maxMeshVelocity");
  o.maxDeltaDispFrac = c.get<double>("maxDeltaDispFrac");
  o.motion.method = c.get<std::string>("meshMotion.method") == "jacobi" ? coupling::MeshMotionMethod::Jacobi
                                                                        : coupling::MeshMotionMethod::ConjugateGradient;
  o.motion.sweeps = c.get<int>("meshMotion.sweeps");
  o.motion.relTol = c.get<double>("meshMotion.relTol");
  o.motion.distanceExponent = c.get<double>("meshMotion.distanceExponent");
  o.motion.maxIterations = c.get<int>("meshMotion.maxIterations");
  o.motion.preconditioner = c.get<std::string>("meshMotion.preconditioner") == "amg" ? LaplacianPreconditioner::Amg
                                                                                   : LaplacianPreconditioner::Jacobi;
  o.motion.minScaledJacobian = c.get<double>("meshMotion.minScaledJacobian");
  o.motion.retries = c.get<int>("meshMotion.retries");
  o.motion.slidingPatches = c.get<std::vector<std::string>>("meshMotion.slidingPatches");
  o.motion.columns = c.get<bool>("meshMotion.columns");
  for (const auto& name : c.keys("bodyPatches"))
    o.bodyPatches.push_back({name, c.get<std::vector<std::string>>("bodyPatches." + name)});
  for (const auto& name : c.keys("meshMotion.bodies")) {
    const std::string key = "meshMotion.bodies." + name;
    CouplingOptions::BodyReach r{name, c.get<double>(key + ".innerDistance"), c.get<double>(key + ".outerDistance")};
    if (!(r.outerDistance > r.innerDistance))
      throw InputError(c.where(key + ".outerDistance"), "outerDistance must exceed innerDistance (" +
                                                             std::to_string(r.innerDistance) + ")");
    if (std::find_if(o.bodyPatches.begin(), o.bodyPatches.end(),
                     [&](const CouplingOptions::BodyPatches& b) { return b.body == name; }) == o.bodyPatches.end())
      throw InputError(c.where(key), "body '" + name + "' is not one of coupling.bodyPatches");
    o.bodyReach.push_back(r);
  }
  if (c.has("lumpedChamber")) {
    o.lumpedChamber.membrane = c.get<std::string>("lumpedChamber.membrane");
    o.lumpedChamber.flowRate = c.get<double>("lumpedChamber.flowRate");
    if (c.has("lumpedChamber.timeFunction"))
      o.lumpedChamber.timeFunction = readTimeFunction(c.child("lumpedChamber.timeFunction"));
  }
  for (const auto& name : c.keys("parentBodyPatches"))
    o.parentBodyPatches.push_back({name, c.get<std::vector<std::string>>("parentBodyPatches." + name)});
  return o;
}

}  // namespace mfsi
