#include "structure/membrane/MembraneConfig.hpp"

#include "structure/membrane/HenckySolution.hpp"

#include "core/Suggest.hpp"
#include "structure/membrane/MembraneMeshImport.hpp"
#include "structure/membrane/MembraneOnRanks.hpp"

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <set>

namespace mfsi {

namespace {

Schema timeSchema(const std::string& what = "multiplier f(t) of the uniform pressure") {
  return Schema::map(what)
      .key("shape",
           Schema::choice("constant: 1; ramp: min(1, t/rampTime); sine: offset + amplitude sin(omega t + phase); "
                          "pulse: 1 for t < duration, then 0",
                          {"constant", "ramp", "sine", "pulse"}),
           Default("constant"))
      .key("rampTime", Schema::real("ramp: time to reach the full load", "s").atLeast(0), Default(0.0))
      .key("duration", Schema::real("pulse: duration", "s").atLeast(0), Default(0.0))
      .key("amplitude", Schema::real("sine: amplitude", "-"), Default(0.0))
      .key("omega", Schema::real("sine: angular frequency", "rad/s"), Default(0.0))
      .key("phase", Schema::real("sine: phase", "rad"), Default(0.0))
      .key("offset", Schema::real("sine: offset", "-"), Default(0.0));
}

Schema elementsChoice() { return Schema::choice("element type", {"quads", "triangles"}); }

Schema meshSchemaOfPanel() {
  const MembraneRectangleSpec r;
  const MembraneDiscSpec d;
  const MembraneAnnulusSpec a;
  const MembraneSphereSpec s;
  Schema rectangle =
      Schema::map("flat rectangle at z = origin.z, normal +z; node sets xmin xmax ymin ymax corners boundary centre")
          .key("origin", Schema::realVector(3, "corner with the smallest x and y", "m"), Default(r.origin))
          .key("size", Schema::realVector(2, "side lengths lx, ly", "m").greaterThan(0),
               Default(std::array<double, 2>{r.lx, r.ly}))
          .key("cells", Schema::intVector(2, "cells along x, y").atLeast(1), Default(std::array<int, 2>{r.nx, r.ny}))
          .key("elements", elementsChoice(), Default("quads"));
  Schema disc = Schema::map("flat disc (normal +z) meshed by an O-grid; node sets boundary centre")
                    .key("centre", Schema::realVector(3, "disc centre", "m"), Default(d.centre))
                    .key("radius", Schema::real("radius", "m").greaterThan(0), Default(d.radius))
                    .key("core", Schema::integer("cells per side of the core square").atLeast(1), Default(d.nCore))
                    .key("rings", Schema::integer("cells from the core square to the rim").atLeast(1), Default(d.nRing))
                    .key("coreFraction",
                         Schema::real("radius of the core square corners / radius", "-").greaterThan(0).lessThan(1),
                         Default(d.coreFraction))
                    .key("ringGrading", Schema::real("outermost / innermost ring cell size", "-").greaterThan(0),
                         Default(d.ringGrading))
                    .key("elements", elementsChoice(), Default("quads"));
  Schema annulus = Schema::map("flat annulus (normal +z); node sets inner outer boundary centre")
                       .key("centre", Schema::realVector(3, "centre", "m"), Default(a.centre))
                       .key("innerRadius", Schema::real("inner radius", "m").greaterThan(0), Default(a.innerRadius))
                       .key("outerRadius", Schema::real("outer radius", "m").greaterThan(0), Default(a.outerRadius))
                       .key("radialCells", Schema::integer("cells across the ring").atLeast(1), Default(a.nRadial))
                       .key("segments", Schema::integer("cells around").atLeast(3), Default(a.nTheta))
                       .key("radialGrading", Schema::real("outer / inner radial cell size", "-").greaterThan(0),
                            Default(a.radialGrading));
  Schema sphere = Schema::map("closed cube-sphere (outward normals, no boundary); node set centre (+z pole)")
                      .key("centre", Schema::realVector(3, "centre", "m"), Default(s.centre))
                      .key("radius", Schema::real("radius", "m").greaterThan(0), Default(s.radius))
                      .key("faceCells", Schema::integer("cells per cube-face side").atLeast(1), Default(s.n));
  Schema gmsh = Schema::map("surface mesh from a Gmsh 4.1 ASCII file (quads and/or triangles; line groups become node sets)")
                    .key("file", Schema::path("Gmsh .msh file, relative to the scene"))
                    .key("group", Schema::string("physical surface group (empty: all surface elements)"), Default(""));
  Schema baffles = Schema::map("surface taken from a baffle of the scene's fluid mesh (nodes shared with the fluid)")
                       .key("patch", Schema::string("baffle name (mesh.baffles name, without _master/_slave)"));
  Schema onPatch =
      Schema::map("surface taken from a one-sided boundary patch of the scene's fluid mesh (a wall the membrane "
                  "replaces; normal out of the fluid); node sets xmin ... zmax of its bounding box")
          .key("patch", Schema::string("patch name"));
  return Schema::map("surface mesh: exactly one generator")
      .key("rectangle", rectangle, Presence::OptionalSection)
      .key("disc", disc, Presence::OptionalSection)
      .key("annulus", annulus, Presence::OptionalSection)
      .key("sphere", sphere, Presence::OptionalSection)
      .key("gmsh", gmsh, Presence::OptionalSection)
      .key("baffles", baffles, Presence::OptionalSection)
      .key("boundaryPatch", onPatch, Presence::OptionalSection);
}

Schema panelSchema() {
  const MembraneOptions o;
  const MembraneLoads l;
  const MembraneDynamicsOptions dyn;
  Schema material =
      Schema::map("St. Venant-Kirchhoff plane-stress material")
          .key("E", Schema::real("Young's modulus", "Pa").greaterThan(0))
          .key("nu", Schema::real("Poisson's ratio", "-").atLeast(0).atMost(0.5), Default(o.material.poissonRatio))
          .key("thickness", Schema::real("thickness h", "m").greaterThan(0))
          .key("density", Schema::real("density rho (needed by dynamics)", "kg/m^3").atLeast(0),
               Default(o.material.density))
          .key("preStress", Schema::real("isotropic membrane pre-stress T0 (force per length)", "N/m"),
               Default(o.material.preStress))
          .key("bending",
               Schema::choice("none: a membrane; plate: add rotation-free plate bending, D = E h^3 / (12 (1 - nu^2)) "
                              "(hinges on the displacement dofs; quad meshes; rims simply supported)",
                              {"none", "plate"}),
               Default("none"));
  Schema solver =
      Schema::map("nonlinear solver of static solves (time steps always use consistent-tangent Newton)")
          .key("method",
               Schema::choice("newton: consistent tangent + CG + line search; lumped: lumped Newton-Raphson",
                              {"newton", "lumped"}),
               Default("newton"))
          .key("tolerance",
               Schema::real("relative residual: ||R|| <= tol * max(||F_ext||, ||reactions||, ||R_0||)", "-")
                   .greaterThan(0),
               Default(o.tolerance))
          .key("loadSteps", Schema::integer("equal load increments of a static solve").atLeast(1), Default(o.loadSteps))
          .key("maxIterations",
               Schema::integer("nonlinear iterations per solve (0: method default, " +
                               std::to_string(o.newton.maxIterations) + " newton / " +
                               std::to_string(o.lumped.maxIterations) + " lumped)")
                   .atLeast(0),
               Default(0))
          .key("characteristicLength",
               Schema::real("length of the displacement limiters (0: sqrt(area))", "m").atLeast(0),
               Default(o.characteristicLength))
          .key("lineSearchSteps",
               Schema::integer("residual evaluations a Newton step may add to find the root of du . R along it "
                               "(static solves and time steps; 0: the full step)")
                   .atLeast(0),
               Default(o.newton.maxLineSearchSteps))
          .key("tangentStressFloor",
               Schema::real("tangent-only floor of the smallest principal membrane force, as a fraction of E h: "
                            "gives a flat unstressed sheet a first Newton matrix and keeps compressed ones positive "
                            "definite; 0: the exact tangent (quadratic Newton; a time step's mass keeps its matrix "
                            "definite unless the sheet carries compression, i.e. with tension-field wrinkling)",
                            "-")
                   .atLeast(0),
               Default(o.newton.tangentStressFloor));
  Schema dynamics =
      Schema::map("implicit time integration (analysis: dynamic)")
          .key("integrator", Schema::choice("time integrator", {"newmark", "generalizedAlpha"}), Default("newmark"))
          .key("beta", Schema::real("Newmark beta", "-").greaterThan(0), Default(dyn.beta))
          .key("gamma", Schema::real("Newmark gamma", "-").atLeast(0.5), Default(dyn.gamma))
          .key("rhoInfinity",
               Schema::real("generalized-alpha high-frequency spectral radius", "-").atLeast(0).atMost(1),
               Default(dyn.rhoInfinity))
          .key("mass", Schema::choice("mass matrix", {"consistent", "lumped"}), Default("consistent"))
          .key("rayleighAlpha", Schema::real("Rayleigh damping C = alpha M + beta K: alpha", "1/s").atLeast(0),
               Default(dyn.rayleighAlpha))
          .key("rayleighBeta", Schema::real("Rayleigh damping: beta", "s").atLeast(0), Default(dyn.rayleighBeta));
  Schema loads =
      Schema::map("pressure loads: p = pressure f(t) + s pOffset min(1, t / pOffsetRamp), positive along the normal")
          .key("pressure", Schema::real("uniform pressure", "Pa"), Default(l.pressure))
          .key("time", timeSchema(), Presence::Optional)
          .key("direction",
               Schema::choice("follower: current normal and area; dead: reference ones", {"follower", "dead"}),
               Default("follower"))
          .key("integration",
               Schema::choice("consistent: Gauss integration; lumped: equal nodal shares", {"consistent", "lumped"}),
               Default("consistent"))
          .key("pOffset", Schema::real("offset pressure that always inflates (sign from insidePoint)", "Pa"),
               Default(l.pressureOffset))
          .key("insidePoint", Schema::realVector(3, "a point inside the inflated volume (pOffset sign)", "m"),
               Default(l.insidePoint))
          .key("pOffsetRamp", Schema::real("ramp time of pOffset (0: at once)", "s").atLeast(0),
               Default(l.pressureOffsetRampTime));
  Schema spring = Schema::map("springs from each node of a node set to its reference position")
                      .key("nodes", Schema::string("node set"))
                      .key("stiffness", Schema::real("stiffness per node", "N/m").atLeast(0))
                      .key("restLength", Schema::real("rest length (< 0: the reference distance)", "m"), Default(-1.0));
  Schema beam =
      Schema::map("axial bars (edge cables/beams) along a node set; 'boundary' follows the closed boundary loops")
          .key("nodes", Schema::string("node set"))
          .key("axialStiffness", Schema::real("EA", "N").atLeast(0))
          .key("tensionOnly", Schema::boolean("cable: no compression"), Default(false));
  Schema boundary =
      Schema::map("boundary conditions by node set")
          .key("clamp", Schema::list("node sets held fixed", Schema::string("node set")),
               Default::fromYaml("[boundary]"))
          .key("constrainToNormal",
               Schema::list("node sets moving only along their reference normal", Schema::string("node set")),
               Presence::Optional)
          .key("springs", Schema::list("node springs", spring), Presence::Optional)
          .key("edgeBeams", Schema::list("edge reinforcements", beam), Presence::Optional)
          .key("clampMotion",
               Schema::list("clamped node sets that move: each node to X + translation f(t) (a frame's edge "
                            "closing in, stretching or compressing the sheet); a node of a moving set leaves "
                            "the fixed clamps (boundary.clamp)",
                            Schema::map("a moving clamp")
                                .key("nodes", Schema::string("node set"))
                                .key("translation", Schema::realVector(3, "displacement at f = 1", "m"))
                                .key("time", timeSchema("multiplier f(t) of the translation"), Presence::Optional)),
               Presence::Optional)
          .key("motionPlaneNormal",
               Schema::realVector(3, "nonzero: unclamped nodes move perpendicular to it only (a one-cell-thick 2D "
                                     "scene gives its thickness axis, e.g. [0, 0, 1])",
                                  "-"),
               Default(std::array<double, 3>{0, 0, 0}));
  Schema initial =
      Schema::map("initial displacement")
          .key("shape", Schema::choice("flat, or (rectangle) a sine mode along the normal", {"flat", "sineMode"}),
               Default("flat"))
          .key("mode", Schema::intVector(2, "half-waves m, n along x, y").atLeast(1), Default(std::array<int, 2>{1, 1}))
          .key("amplitude", Schema::real("peak deflection", "m"), Default(0.0));
  return Schema::map("a membrane panel")
      .key("name", Schema::string("panel name: module 'membrane.<name>' (default: 'membrane', or by index)"),
           Default(""))
      .key("mesh", meshSchemaOfPanel())
      .key("material", material)
      .key("wrinkling", Schema::choice("wrinkling model", {"none", "tensionField"}), Default("none"))
      .key("wrinklingStiffnessFraction",
           Schema::real("safeguard stiffness of the tension-field tangent", "-").atLeast(0),
           Default(o.wrinklingStiffnessFraction))
      .key("wrinklingResidualStiffness",
           Schema::real("fraction f of the elastic law a wrinkled or slack point keeps, in its stress too: "
                        "N = (1 - f) N_tensionField + f h C E (0: the pure tension field; a slack sheet then has no "
                        "in-plane stiffness and its nodes drift in its plane)",
                        "-")
               .atLeast(0)
               .atMost(1),
           Default(o.wrinklingResidualStiffness))
      .key("analysis",
           Schema::choice("static: equilibrium at the start and at the end of every step; dynamic: implicit dynamics",
                          {"static", "dynamic"}),
           Default("static"))
      .key("solver", solver, Presence::Optional)
      .key("dynamics", dynamics, Presence::Optional)
      .key("loads", loads, Presence::Optional)
      .key("boundary", boundary, Presence::Optional)
      .key("initial", initial, Presence::Optional)
      .key("reference",
           Schema::choice("analytic solution compared in the metrics", {"none", "hencky", "squareFrequency"}),
           Default("none"));
}

MembraneElementType elementType(const SceneConfig& c) {
  return c.get<std::string>("elements") == "triangles" ? MembraneElementType::Tri3 : MembraneElementType::Quad4;
}

MembraneMeshSpec readMesh(const SceneConfig& m, const HexMesh* fluidMesh, MPI_Comm fluidComm) {
  std::vector<std::string> given;
  for (const auto& k : {"rectangle", "disc", "annulus", "sphere", "gmsh", "baffles", "boundaryPatch"})
    if (m.has(k)) given.push_back(k);
  if (given.size() != 1)
    throw InputError(m.where(), "give exactly one mesh generator (rectangle, disc, annulus, sphere, gmsh, baffles, "
                                "boundaryPatch), got " +
                                    (given.empty() ? std::string("none") : joinList(given)));
  MembraneMeshSpec s;
  const std::string g = given.front();
  const SceneConfig c = m.child(g);
  if (g == "gmsh") {
    s.kind = MembraneMeshKind::Gmsh;
    std::filesystem::path f = c.get<std::string>("file");
    if (f.is_relative()) f = std::filesystem::path(m.file()).parent_path() / f;
    if (!std::filesystem::exists(f)) throw InputError(c.where("file"), "surface mesh file not found: " + f.string());
    s.gmshFile = f.string();
    s.gmshGroup = c.get<std::string>("group");
    return s;
  }
  if (g == "baffles") {
    if (fluidMesh == nullptr)
      throw InputError(c.where("patch"), "a membrane on a baffle needs the scene's 'mesh' section with that baffle");
    s.kind = MembraneMeshKind::Baffle;
    s.baffle = c.get<std::string>("patch");
    s.fluidMesh = fluidMesh;
    if (fluidMesh->findPatch(s.baffle + "_master") < 0) {
      std::vector<std::string> names;
      for (const auto& pt : fluidMesh->patches())
        if (pt.kind == PatchKind::BaffleMaster) names.push_back(pt.name.substr(0, pt.name.size() - 7));
      throw InputError(c.where("patch"), "the fluid mesh has no baffle '" + s.baffle + "'" + didYouMean(s.baffle, names) +
                                             "; baffles: " + (names.empty() ? std::string("none") : joinList(names)));
    }
    if (fluidComm != MPI_COMM_NULL)
      s.surface = std::make_shared<const FluidSurfaceMembraneInput>(
          cutMembraneOnRanks(*fluidMesh, {s.baffle, true}, fluidComm));
    return s;
  }
  if (g == "boundaryPatch") {
    if (fluidMesh == nullptr)
      throw InputError(c.where("patch"), "a membrane on a boundary patch needs the scene's 'mesh' section");
    s.kind = MembraneMeshKind::Patch;
    s.patch = c.get<std::string>("patch");
    s.fluidMesh = fluidMesh;
    const int pi = fluidMesh->findPatch(s.patch);
    std::vector<std::string> names;
    for (const auto& pt : fluidMesh->patches())
      if (pt.kind != PatchKind::BaffleMaster && pt.kind != PatchKind::BaffleSlave) names.push_back(pt.name);
    if (pi < 0 || std::find(names.begin(), names.end(), s.patch) == names.end())
      throw InputError(c.where("patch"), "the fluid mesh has no one-sided boundary patch '" + s.patch + "'" +
                                             didYouMean(s.patch, names) + "; patches: " + joinList(names));
    if (fluidComm != MPI_COMM_NULL)
      s.surface = std::make_shared<const FluidSurfaceMembraneInput>(
          cutMembraneOnRanks(*fluidMesh, {s.patch, false}, fluidComm));
    return s;
  }
  if (g == "rectangle") {
    s.kind = MembraneMeshKind::Rectangle;
    s.rectangle.origin = c.get<std::array<double, 3>>("origin");
    const auto size = c.get<std::array<double, 2>>("size");
    const auto cells = c.get<std::array<int, 2>>("cells");
    s.rectangle.lx = size[0];
    s.rectangle.ly = size[1];
    s.rectangle.nx = cells[0];
    s.rectangle.ny = cells[1];
    s.rectangle.type = elementType(c);
  } else if (g == "disc") {
    s.kind = MembraneMeshKind::Disc;
    s.disc.centre = c.get<std::array<double, 3>>("centre");
    s.disc.radius = c.get<double>("radius");
    s.disc.nCore = c.get<int>("core");
    s.disc.nRing = c.get<int>("rings");
    s.disc.coreFraction = c.get<double>("coreFraction");
    s.disc.ringGrading = c.get<double>("ringGrading");
    s.disc.type = elementType(c);
  } else if (g == "annulus") {
    s.kind = MembraneMeshKind::Annulus;
    s.annulus.centre = c.get<std::array<double, 3>>("centre");
    s.annulus.innerRadius = c.get<double>("innerRadius");
    s.annulus.outerRadius = c.get<double>("outerRadius");
    s.annulus.nRadial = c.get<int>("radialCells");
    s.annulus.nTheta = c.get<int>("segments");
    s.annulus.radialGrading = c.get<double>("radialGrading");
    if (s.annulus.innerRadius >= s.annulus.outerRadius)
      throw InputError(c.where("innerRadius"), "must be smaller than outerRadius");
  } else {
    s.kind = MembraneMeshKind::Sphere;
    s.sphere.centre = c.get<std::array<double, 3>>("centre");
    s.sphere.radius = c.get<double>("radius");
    s.sphere.n = c.get<int>("faceCells");
  }
  return s;
}

MembraneTimeFunction readTime(const SceneConfig& t) {
  MembraneTimeFunction f;
  const std::string shape = t.get<std::string>("shape");
  f.shape = shape == "ramp"    ? MembraneTimeShape::Ramp
            : shape == "sine"  ? MembraneTimeShape::Sine
            : shape == "pulse" ? MembraneTimeShape::Pulse
                               : MembraneTimeShape::Constant;
  f.rampTime = t.get<double>("rampTime");
  f.duration = t.get<double>("duration");
  f.amplitude = t.get<double>("amplitude");
  f.omega = t.get<double>("omega");
  f.phase = t.get<double>("phase");
  f.offset = t.get<double>("offset");
  if (f.shape == MembraneTimeShape::Ramp && f.rampTime <= 0)
    throw InputError(t.where("rampTime"), "a ramp needs rampTime > 0");
  if (f.shape == MembraneTimeShape::Pulse && f.duration <= 0)
    throw InputError(t.where("duration"), "a pulse needs duration > 0");
  return f;
}

/// Node-set names a scene may use on a mesh input (buildMembraneMesh adds "boundary" and "centre").
std::vector<std::string> knownSets(const MembraneMeshInput& in) {
  std::set<std::string> s = {"boundary", "centre"};
  for (const auto& [name, nodes] : in.nodeSets) s.insert(name);
  return {s.begin(), s.end()};
}

void checkSet(const SceneConfig& c, const std::string& key, const std::string& name,
              const std::vector<std::string>& known) {
  if (std::find(known.begin(), known.end(), name) == known.end())
    throw InputError(c.where(key), "unknown node set '" + name + "'" + didYouMean(name, known) +
                                       "; the mesh has: " + joinList(known));
}

MembraneBoundarySpec readBoundary(const SceneConfig& b, const std::vector<std::string>& known) {
  MembraneBoundarySpec s;
  s.clamp = b.get<std::vector<std::string>>("clamp");
  s.constrainToNormal = b.get<std::vector<std::string>>("constrainToNormal");
  s.motionPlaneNormal = b.get<std::array<double, 3>>("motionPlaneNormal");
  for (std::size_t i = 0; i < s.clamp.size(); ++i) checkSet(b, "clamp." + std::to_string(i), s.clamp[i], known);
  for (std::size_t i = 0; i < s.constrainToNormal.size(); ++i)
    checkSet(b, "constrainToNormal." + std::to_string(i), s.constrainToNormal[i], known);
  for (std::size_t i = 0; i < b.size("springs"); ++i) {
    const SceneConfig c = b.child("springs." + std::to_string(i));
    MembraneSetSprings sp{c.get<std::string>("nodes"), c.get<double>("stiffness"), c.get<double>("restLength")};
    checkSet(c, "nodes", sp.nodeSet, known);
    s.springs.push_back(sp);
  }
  for (std::size_t i = 0; i < b.size("clampMotion"); ++i) {
    const SceneConfig c = b.child("clampMotion." + std::to_string(i));
    MembraneClampMotion m{c.get<std::string>("nodes"), c.get<std::array<double, 3>>("translation"),
                          readTime(c.child("time"))};
    checkSet(c, "nodes", m.nodeSet, known);
    for (const auto& other : s.clampMotion)
      if (other.nodeSet == m.nodeSet) throw InputError(c.where("nodes"), "'" + m.nodeSet + "' moves twice");
    s.clampMotion.push_back(m);
  }
  for (std::size_t i = 0; i < b.size("edgeBeams"); ++i) {
    const SceneConfig c = b.child("edgeBeams." + std::to_string(i));
    MembraneSetBeams bm{c.get<std::string>("nodes"), c.get<double>("axialStiffness"), c.get<bool>("tensionOnly")};
    checkSet(c, "nodes", bm.nodeSet, known);
    s.edgeBeams.push_back(bm);
  }
  return s;
}

MembranePanelOptions readPanel(const SceneConfig& p, std::size_t index, std::size_t count, const HexMesh* fluidMesh,
                               MPI_Comm fluidComm) {
  MembranePanelOptions o;
  const std::string name = p.get<std::string>("name");
  if (name.find('.') != std::string::npos) throw InputError(p.where("name"), "panel names contain no '.'");
  o.name = !name.empty() ? "membrane." + name : count == 1 ? "membrane" : "membrane." + std::to_string(index);
  o.mesh = readMesh(p.child("mesh"), fluidMesh, fluidComm);

  MembraneOptions& opt = o.options;
  opt.material.youngsModulus = p.get<double>("material.E");
  opt.material.poissonRatio = p.get<double>("material.nu");
  opt.material.thickness = p.get<double>("material.thickness");
  opt.material.density = p.get<double>("material.density");
  opt.material.preStress = p.get<double>("material.preStress");
  opt.material.bending = p.get<std::string>("material.bending") == "plate";
  if (opt.material.bending && p.child("mesh").has("rectangle") && p.child("mesh").child("rectangle").get<std::string>(
                                                                        "elements") == "triangles")
    throw InputError(p.where("material.bending"), "plate bending needs a quad membrane mesh (its hinge constants are "
                                                  "calibrated for quads), and mesh.rectangle.elements is triangles");
  opt.wrinkling = p.get<std::string>("wrinkling") == "tensionField" ? MembraneWrinklingModel::TensionField
                                                                    : MembraneWrinklingModel::None;
  opt.wrinklingStiffnessFraction = p.get<double>("wrinklingStiffnessFraction");
  opt.wrinklingResidualStiffness = p.get<double>("wrinklingResidualStiffness");
  opt.solver = p.get<std::string>("solver.method") == "lumped" ? MembraneStaticSolver::LumpedNewtonRaphson
                                                               : MembraneStaticSolver::Newton;
  opt.tolerance = p.get<double>("solver.tolerance");
  opt.loadSteps = p.get<int>("solver.loadSteps");
  if (const int it = p.get<int>("solver.maxIterations"); it > 0)
    opt.newton.maxIterations = opt.lumped.maxIterations = it;
  opt.characteristicLength = p.get<double>("solver.characteristicLength");
  opt.newton.tangentStressFloor = p.get<double>("solver.tangentStressFloor");
  opt.newton.maxLineSearchSteps = p.get<int>("solver.lineSearchSteps");
  opt.dynamics.integrator = p.get<std::string>("dynamics.integrator") == "generalizedAlpha"
                                ? MembraneTimeIntegrator::GeneralizedAlpha
                                : MembraneTimeIntegrator::Newmark;
  opt.dynamics.beta = p.get<double>("dynamics.beta");
  opt.dynamics.gamma = p.get<double>("dynamics.gamma");
  opt.dynamics.rhoInfinity = p.get<double>("dynamics.rhoInfinity");
  opt.dynamics.mass =
      p.get<std::string>("dynamics.mass") == "lumped" ? MembraneMassType::Lumped : MembraneMassType::Consistent;
  opt.dynamics.rayleighAlpha = p.get<double>("dynamics.rayleighAlpha");
  opt.dynamics.rayleighBeta = p.get<double>("dynamics.rayleighBeta");

  o.analysis = p.get<std::string>("analysis") == "dynamic" ? MembraneAnalysis::Dynamic : MembraneAnalysis::Static;
  if (o.analysis == MembraneAnalysis::Dynamic && opt.material.density <= 0)
    throw InputError(p.where("material.density"), "analysis: dynamic needs density > 0");

  MembraneLoads& l = o.loads;
  l.pressure = p.get<double>("loads.pressure");
  o.pressureTime = readTime(p.child("loads.time"));
  if (o.pressureTime.shape != MembraneTimeShape::Constant) {
    const MembraneTimeFunction f = o.pressureTime;
    l.pressureTime = [f](real t) { return f(t); };
  }
  l.direction = p.get<std::string>("loads.direction") == "dead" ? MembranePressureDirection::Dead
                                                                : MembranePressureDirection::Follower;
  l.integration = p.get<std::string>("loads.integration") == "lumped" ? MembranePressureIntegration::Lumped
                                                                      : MembranePressureIntegration::Consistent;
  l.pressureOffset = p.get<double>("loads.pOffset");
  l.insidePoint = p.get<std::array<double, 3>>("loads.insidePoint");
  l.pressureOffsetRampTime = p.get<double>("loads.pOffsetRamp");

  // The host mesh description is cheap to generate and tells which node sets exist, so unknown
  // names fail here with the scene location rather than deep inside the solver set-up.
  const std::vector<std::string> known = knownSets(generateMembraneMesh(o.mesh));
  o.boundary = readBoundary(p.child("boundary"), known);

  const SceneConfig init = p.child("initial");
  o.initial.shape =
      init.get<std::string>("shape") == "sineMode" ? MembraneInitialShape::SineMode : MembraneInitialShape::Flat;
  o.initial.mode = init.get<std::array<int, 2>>("mode");
  o.initial.amplitude = init.get<double>("amplitude");
  if (o.initial.shape == MembraneInitialShape::SineMode && o.mesh.kind != MembraneMeshKind::Rectangle)
    throw InputError(init.where("shape"), "a sineMode initial shape needs a rectangle mesh");

  const std::string ref = p.get<std::string>("reference");
  const bool clampsBoundary =
      std::find(o.boundary.clamp.begin(), o.boundary.clamp.end(), "boundary") != o.boundary.clamp.end();
  if (ref == "hencky") {
    o.reference = MembraneReference::Hencky;
    auto need = [&](bool ok, const std::string& key, const std::string& what) {
      if (!ok) throw InputError(p.where(key), "reference: hencky needs " + what);
    };
    need(o.mesh.kind == MembraneMeshKind::Disc, "mesh", "a disc mesh");
    need(clampsBoundary, "boundary.clamp", "the boundary clamped");
    need(l.pressure != 0, "loads.pressure", "a non-zero uniform pressure");
    need(opt.material.preStress == 0, "material.preStress", "no pre-stress");
    need(o.analysis == MembraneAnalysis::Static, "analysis", "analysis: static");
  } else if (ref == "squareFrequency") {
    o.reference = MembraneReference::SquareFrequency;
    auto need = [&](bool ok, const std::string& key, const std::string& what) {
      if (!ok) throw InputError(p.where(key), "reference: squareFrequency needs " + what);
    };
    need(o.mesh.kind == MembraneMeshKind::Rectangle, "mesh", "a rectangle mesh");
    need(clampsBoundary, "boundary.clamp", "the boundary clamped");
    need(opt.material.preStress > 0, "material.preStress", "a positive pre-stress");
    need(o.analysis == MembraneAnalysis::Dynamic, "analysis", "analysis: dynamic");
    need(o.initial.shape == MembraneInitialShape::SineMode && o.initial.amplitude != 0, "initial",
         "a sineMode initial shape with a non-zero amplitude");
  }
  return o;
}

}  // namespace

real MembraneTimeFunction::operator()(real t) const {
  switch (shape) {
    case MembraneTimeShape::Constant:
      return 1;
    case MembraneTimeShape::Ramp:
      return std::min<real>(1, t / rampTime);
    case MembraneTimeShape::Sine:
      return offset + amplitude * std::sin(omega * t + phase);
    case MembraneTimeShape::Pulse:
      return t < duration ? 1 : 0;
  }
  return 1;
}

MembraneMeshInput generateMembraneMesh(const MembraneMeshSpec& spec) {
  switch (spec.kind) {
    case MembraneMeshKind::Rectangle:
      return generateRectangleMesh(spec.rectangle);
    case MembraneMeshKind::Disc:
      return generateDiscMesh(spec.disc);
    case MembraneMeshKind::Annulus:
      return generateAnnulusMesh(spec.annulus);
    case MembraneMeshKind::Sphere:
      return generateSphereMesh(spec.sphere);
    case MembraneMeshKind::Gmsh:
      return readGmshSurface(spec.gmshFile, spec.gmshGroup);
    case MembraneMeshKind::Baffle:
      return spec.surface ? spec.surface->mesh : membraneMeshFromBaffle(*spec.fluidMesh, spec.baffle).mesh;
    case MembraneMeshKind::Patch:
      return spec.surface ? spec.surface->mesh : membraneMeshFromPatch(*spec.fluidMesh, spec.patch).mesh;
  }
  return {};
}

MembraneBoundary resolveMembraneBoundary(const MembraneBoundarySpec& spec, const MembraneMesh& mesh) {
  MembraneBoundary b;
  // Moving clamps first; their nodes leave the fixed sets (a node has one target).
  std::set<lid_t> moving;
  for (const auto& m : spec.clampMotion) {
    const std::vector<lid_t>& nodes = mesh.nodeSet(m.nodeSet);
    for (lid_t n : nodes)
      if (!moving.insert(n).second)
        throw InputError("membrane boundary.clampMotion: node " + std::to_string(n) + " is in two moving sets ('" +
                         m.nodeSet + "' and another)");
    const MembraneTimeFunction f = m.time;
    const std::array<real, 3> d = m.translation;
    b.clamps.push_back({nodes, {}, [f, d](real t) {
                          RigidPlacement p;
                          const real s = f(t);
                          for (int k = 0; k < 3; ++k) p.placed[k] = s * d[k];
                          return p;
                        }});
  }
  for (const auto& s : spec.clamp) {
    std::vector<lid_t> fixed;
    for (lid_t n : mesh.nodeSet(s))
      if (!moving.count(n)) fixed.push_back(n);
    if (!fixed.empty()) b.clamps.push_back({fixed, {}, {}});
  }
  b.motionPlaneNormal = spec.motionPlaneNormal;
  for (const auto& s : spec.constrainToNormal) {
    const auto& nodes = mesh.nodeSet(s);
    b.normalNodes.insert(b.normalNodes.end(), nodes.begin(), nodes.end());
  }
  for (const auto& sp : spec.springs)
    for (lid_t n : mesh.nodeSet(sp.nodeSet)) {
      MembraneNodeSpring s;
      s.node = n;
      s.anchor = mesh.hostPoints()[n];
      s.stiffness = sp.stiffness;
      s.restLength = sp.restLength;
      b.edgeSprings.push_back(s);
    }
  for (const auto& bm : spec.edgeBeams) {
    if (bm.nodeSet == "boundary") {
      for (const auto& loop : mesh.boundaryLoops()) {
        const auto bars = makeEdgeBeams(loop, bm.axialStiffness, true, bm.tensionOnly);
        b.edgeBeams.insert(b.edgeBeams.end(), bars.begin(), bars.end());
      }
    } else {
      const auto bars = makeEdgeBeams(mesh.nodeSet(bm.nodeSet), bm.axialStiffness, false, bm.tensionOnly);
      b.edgeBeams.insert(b.edgeBeams.end(), bars.begin(), bars.end());
    }
  }
  return b;
}

Schema membraneSchema() {
  return Schema::list("membrane panels, each with its own mesh, material, loads and boundary", panelSchema(), 1);
}

std::vector<MembranePanelOptions> readMembraneOptions(const SceneConfig& membranes, const HexMesh* fluidMesh,
                                                      MPI_Comm fluidComm) {
  std::vector<MembranePanelOptions> panels;
  const std::size_t n = membranes.size();
  for (std::size_t i = 0; i < n; ++i) {
    const SceneConfig p = membranes.child(std::to_string(i));
    panels.push_back(readPanel(p, i, n, fluidMesh, fluidComm));
    for (std::size_t j = 0; j + 1 < panels.size(); ++j)
      if (panels[j].name == panels.back().name)
        throw InputError(p.where("name"), "two panels named '" + panels.back().name + "'");
  }
  return panels;
}

double henckyCoefficient(double nu) { return henckySolution(nu).deflection; }

double rectangleMembraneFrequency(double T0, double rhoH, double lx, double ly, int m, int n) {
  return 0.5 * std::sqrt(T0 / rhoH) * std::sqrt((m / lx) * (m / lx) + (n / ly) * (n / ly));
}

}  // namespace mfsi
