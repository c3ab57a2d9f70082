#include "coupling/Simulation.hpp"

#include "core/MeshConfig.hpp"

#include <cmath>

namespace mfsi {

Schema sceneSchema() {
  Schema s = Schema::map("a membrane-fsi scene");
  s.key("name", Schema::string("scene name (default: the file name)"), Default(""))
      .key("description", Schema::string("what the scene demonstrates"), Default(""))
      .key("mesh", meshSchema(), Presence::OptionalSection)
      .key("time", Schema::map("time stepping")
                       .key("endTime", Schema::real("simulated end time (0: no stepping)", "s").atLeast(0), Default(0.0))
                       .key("dt", Schema::real("time step", "s").atLeast(0), Default(0.0))
                       .key("maxSteps", Schema::integer("stop after this many steps (0: no limit)").atLeast(0), Default(0)),
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
  if (time_.endTime > 0 && time_.dt <= 0)
    throw InputError(scene.where("time.dt"), "a positive time step is needed when time.endTime > 0");

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

RunResult Simulation::run(const std::string& outDir, bool terminal) {
  RunResult r;
  long long nSteps = 0;
  if (time_.endTime > 0) {
    nSteps = static_cast<long long>(std::ceil(time_.endTime / time_.dt - 1e-9));
    if (time_.maxSteps > 0) nSteps = std::min<long long>(nSteps, time_.maxSteps);
  }
  std::vector<std::string> columns = {"step", "time", "wall_s"};
  for (const Module* m : reporting_)
    for (const auto& c : m->stepColumns()) columns.push_back(m->name() + "." + c);
  StepLog log(outDir + "/steps.csv", columns);
  for (Module* m : reporting_) m->openOutput(outDir);
  Progress progress(nSteps, time_.endTime, terminal);
  TimeState ts;
  ts.endTime = time_.endTime;
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
    progress.update(ts.step, ts.time);
  }
  progress.finish();
  r.steps = ts.step;
  r.simTime = ts.time;
  {
    ScopedTimer t(timers_, "metrics");
    meshMetrics(r.metrics);
    for (const Module* m : reporting_) m->addMetrics(r.metrics);
  }
  return r;
}

}  // namespace mfsi
