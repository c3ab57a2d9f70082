#include "coupling/Simulation.hpp"

#include "core/MeshConfig.hpp"
#include "core/io/HostCopy.hpp"

#include <cmath>

namespace mfsi {

namespace {
/// Steps a scene may ask for: a billion-step run of the smallest scene takes weeks.
constexpr double kMaxSteps = 1e9;
}  // namespace

Schema sceneSchema() {
  Schema s = Schema::map("a membrane-fsi scene");
  s.key("name", Schema::string("scene name (default: the file name)"), Default(""))
      .key("description", Schema::string("what the scene demonstrates"), Default(""))
      .key("mesh", meshSchema(), Presence::OptionalSection)
      .key("time", Schema::map("time stepping")
                       .key("endTime", Schema::real("simulated end time (0: no stepping)", "s").atLeast(0), Default(0.0))
                       .key("dt", Schema::real("time step", "s").atLeast(0), Default(0.0))
                       .key("maxSteps", Schema::integer("stop after this many steps (0: no limit)").atLeast(0), Default(0)),
           Presence::Optional)
      .key("output",
           Schema::map("results written during the run (summary.json and steps.csv are always written)")
               .key("fields",
                    Schema::map("fields for ParaView: one HDF5 file per frame in fields/, listed in fields.xdmf "
                                "(open fields.xdmf)")
                        .key("interval", Schema::real("a frame every this much simulated time (0: not by time)", "s")
                                             .atLeast(0), Default(0.0))
                        .key("everySteps", Schema::integer("a frame every this many steps (0: not by steps)").atLeast(0),
                             Default(0))
                        .key("initial", Schema::boolean("a frame of the state at the start"), Default(false))
                        .key("final", Schema::boolean("a frame of the state at the end of the run"), Default(true)),
                    Presence::Optional),
           Presence::Optional);
  for (const auto& entry : moduleCatalogue()) s.key(entry.section, entry.schema(), Presence::OptionalSection);
  return s;
}

Simulation::Simulation(const SceneConfig& scene) {
  hasMesh_ = scene.has("mesh");
  if (hasMesh_) {
    ScopedTimer t(timers_, "mesh");
    mesh_ = buildMesh(scene.child("mesh"));
    geometry_ = allocateGeometry(mesh_);
    computeGeometry(ExecSpace(), mesh_, geometry_);
    Kokkos::fence();
  }
  time_.endTime = scene.get<double>("time.endTime");
  time_.dt = scene.get<double>("time.dt");
  time_.maxSteps = scene.get<int>("time.maxSteps");
  fieldOutput_.interval = scene.get<double>("output.fields.interval");
  fieldOutput_.everySteps = scene.get<int>("output.fields.everySteps");
  fieldOutput_.initial = scene.get<bool>("output.fields.initial");
  fieldOutput_.final = scene.get<bool>("output.fields.final");
  if (time_.endTime > 0 && time_.dt <= 0)
    throw InputError(scene.where("time.dt"), "a positive time step is needed when time.endTime > 0");
  if (time_.endTime > 0) {
    // Counted in floating point: endTime / dt may exceed what an integer holds.
    double steps = std::ceil(time_.endTime / time_.dt - 1e-9);
    if (time_.maxSteps > 0) steps = std::min(steps, double(time_.maxSteps));
    if (!(steps <= kMaxSteps))
      throw InputError(scene.where("time.dt"), "time.endTime / time.dt asks for " + formatReal(steps) +
                                                   " steps, more than " + formatReal(kMaxSteps) +
                                                   " (a larger dt, or time.maxSteps to stop earlier)");
    nSteps_ = static_cast<long long>(steps);
  }

  SimulationContext ctx;
  if (hasMesh_) {
    ctx.mesh = &mesh_;
    ctx.geometry = &geometry_;
  }
  ctx.timers = &timers_;
  ctx.built = &modules_;
  for (const auto& entry : moduleCatalogue()) {
    if (!scene.has(entry.section)) continue;  // not named: never constructed
    ScopedTimer t(timers_, "setup." + entry.section);
    auto created = entry.create(scene.child(entry.section), ctx);
    for (auto& m : created) modules_.push_back(std::move(m));
  }
  for (auto& m : modules_) {
    reporting_.push_back(m.get());
    for (Module* p : m->parts()) reporting_.push_back(p);
  }
  if (!hasMesh_ && modules_.empty())
    throw InputError(scene.where(), "the scene names nothing to simulate: give at least a 'mesh' or a physics section");
}

void Simulation::meshMetrics(std::map<std::string, double>& m) const {
  if (!hasMesh_) return;
  computeGeometry(ExecSpace(), mesh_, geometry_);  // the mesh may have moved since set-up
  const MeshQuality q = computeQuality(ExecSpace(), mesh_, geometry_);
  m["mesh.min_scaled_jacobian"] = q.minScaledJacobian;
  m["mesh.max_non_orthogonality_deg"] = q.maxNonOrthogonality;
  m["mesh.mean_non_orthogonality_deg"] = q.meanNonOrthogonality;
  m["mesh.max_skewness"] = q.maxSkewness;
  m["mesh.total_volume"] = q.totalVolume;
  m["mesh.min_cell_volume"] = q.minVolume;
  m["mesh.max_cell_volume"] = q.maxVolume;
  m["mesh.internal_faces"] = mesh_.nInternalFaces();
  m["mesh.boundary_faces"] = mesh_.nBoundaryFaces();
  m["mesh.patches"] = static_cast<double>(mesh_.patches().size());
}

io::FieldFrame Simulation::fieldFrame(double time, long long step) {
  io::FieldFrame frame;
  frame.time = time;
  frame.step = step;
  if (hasMesh_) {
    io::OutputGrid g;
    g.name = "mesh";
    g.shape = io::CellShape::Hexahedron;
    const std::size_t nNodes = static_cast<std::size_t>(mesh_.nNodes());
    const std::size_t nCells = static_cast<std::size_t>(mesh_.nCells());
    g.points = io::hostValues(mesh_.points(), nNodes);
    const std::vector<double> x0 = io::hostValues(mesh_.referencePoints(), nNodes);
    std::vector<double> d(g.points.size());
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = g.points[i] - x0[i];
    for (double c : io::hostValues(mesh_.cellNodes(), nCells)) g.cells.push_back(static_cast<std::int64_t>(c));
    RealView quality("mfsi::output::scaledJacobian", nCells);
    cellScaledJacobians(ExecSpace(), mesh_, quality);
    g.addPointField("meshDisplacement", 3, std::move(d), true, true);
    g.addCellField("scaledJacobian", 1, io::hostValues(quality, nCells), true, true);
    frame.grids.push_back(std::move(g));
  }
  // Parts first, then the module that owns them (the coupling moves a mounted membrane's grid to
  // where its frames carry it).
  for (auto& m : modules_) {
    for (Module* p : m->parts()) p->addOutputFields(frame);
    m->addOutputFields(frame);
  }
  return frame;
}

RunResult Simulation::run(const std::string& outDir, bool terminal) {
  RunResult r;
  const long long nSteps = nSteps_;
  std::vector<std::string> columns = {"step", "time", "wall_s"};
  for (const Module* m : reporting_)
    for (const auto& c : m->stepColumns()) columns.push_back(m->name() + "." + c);
  StepLog log(outDir + "/steps.csv", columns);
  for (Module* m : reporting_) m->openOutput(outDir, OutputStart{});
  Progress progress(nSteps, time_.endTime, terminal);
  TimeState ts;
  ts.endTime = time_.endTime;
  io::FieldSeries fields(outDir);
  long long lastFrameStep = -1;
  auto writeFrame = [&] {
    ScopedTimer t(timers_, "output");
    fields.write(fieldFrame(ts.time, ts.step));
    lastFrameStep = ts.step;
  };
  double nextFrameTime = fieldOutput_.interval;
  if (fieldOutput_.initial) writeFrame();
  const double start = wallSeconds();
  for (long long s = 0; s < nSteps; ++s) {
    ts.dtOld = ts.step > 0 ? ts.dt : time_.dt;
    ts.dt = std::min(time_.dt, time_.endTime - ts.time);
    {
      ScopedTimer t(timers_, "advance");
      for (auto& m : modules_) m->advance(ts);
    }
    ts.time += ts.dt;
    ++ts.step;
    completedSteps_ = ts.step;
    completedTime_ = ts.time;
    std::vector<double> row = {double(ts.step), ts.time, wallSeconds() - start};
    for (const Module* m : reporting_) m->appendStepValues(row);
    log.row(row);
    bool frame = fieldOutput_.everySteps > 0 && ts.step % fieldOutput_.everySteps == 0;
    if (fieldOutput_.interval > 0 && ts.time >= nextFrameTime - 1e-9 * ts.dt) {
      frame = true;
      while (nextFrameTime <= ts.time + 1e-9 * ts.dt) nextFrameTime += fieldOutput_.interval;
    }
    if (frame) writeFrame();
    progress.update(ts.step, ts.time);
  }
  if (fieldOutput_.final && lastFrameStep != ts.step) writeFrame();
  progress.finish();
  r.steps = ts.step;
  r.simTime = ts.time;
  {
    ScopedTimer t(timers_, "metrics");
    meshMetrics(r.metrics);
    r.metrics["output.field_frames"] = fields.frames();
    for (const Module* m : reporting_) m->addMetrics(r.metrics);
  }
  return r;
}

}  // namespace mfsi
