#include "coupling/RigidModule.hpp"

#include "core/RunLog.hpp"
#include "structure/rigid/RigidConfig.hpp"

#include <cmath>
#include <sstream>

namespace mfsi {

RigidModule::RigidModule(const RigidSystemOptions& options) : Module("bodies"), system_(options) {
  energy0_ = system_.kineticEnergy() + system_.potentialEnergy();
}

void RigidModule::advance(const TimeState& t) {
  system_.step(t.time, t.dt);
  recordStep();
}

void RigidModule::recordStep() {
  const double e = system_.kineticEnergy() + system_.potentialEnergy();
  if (!std::isfinite(e)) throw DivergenceError("rigid bodies: non-finite energy at t = " + std::to_string(system_.time()));
  maxEnergyDrift_ = std::max(maxEnergyDrift_, std::abs(e - energy0_));
  if (csv_.isOpen()) writeRows();
}

void RigidModule::writeRows() {
  std::ostringstream rows;
  system_.writeCsvRows(rows);
  csv_.append(rows.str());  // one write: a step's rows whole or not at all
}

void RigidModule::addOutputFields(io::FieldFrame& frame) {
  io::OutputGrid g;
  g.name = "bodies";
  g.shape = io::CellShape::Point;
  std::vector<double> velocity, angularVelocity, euler, force, moment;
  auto add = [](std::vector<double>& to, const Eigen::Vector3d& v) { to.insert(to.end(), {v.x(), v.y(), v.z()}); };
  for (int b = 0; b < system_.nBodies(); ++b) {
    const RigidBodyReport r = system_.bodyReport(b);
    add(g.points, r.position);
    add(velocity, r.velocity);
    add(angularVelocity, r.angularVelocity);
    add(euler, r.eulerAngles);
    add(force, r.force);
    add(moment, r.moment);
  }
  g.addPointField("velocity", 3, velocity);
  g.addPointField("angularVelocity", 3, angularVelocity);
  g.addPointField("rollPitchYaw", 3, euler, false);
  g.addPointField("force", 3, force);
  g.addPointField("moment", 3, moment);
  frame.grids.push_back(std::move(g));
}

void RigidModule::addMetrics(std::map<std::string, double>& metrics) const {
  for (const auto& [k, v] : system_.metrics()) metrics["bodies." + k] = v;
  metrics["bodies.maxEnergyDrift"] = maxEnergyDrift_;
}

void RigidModule::openOutput(const std::string& dir, const OutputStart& start) {
  const std::string path = dir + "/bodies.csv";
  csv_ = AppendFile();
  std::ostringstream header;
  RigidBodySystem::writeCsvHeader(header);
  if (start.continueFiles) {
    // nBodies rows at set-up (the state at firstStep) and after every committed step since.
    std::string h = header.str();
    if (!h.empty() && h.back() == '\n') h.pop_back();
    keepCsvRows(path, h, static_cast<long long>(system_.nBodies()) * (start.step - start.firstStep + 1));
    csv_ = AppendFile::open(path);
    return;
  }
  // A new file; a run restarted into a new folder starts it from the checkpoint's state.
  csv_ = AppendFile::create(path, header.str());
  writeRows();
}

std::vector<std::string> RigidModule::stepColumns() const { return {"kineticEnergy", "potentialEnergy", "iterations"}; }

void RigidModule::appendStepValues(std::vector<double>& values) const {
  values.push_back(system_.kineticEnergy());
  values.push_back(system_.potentialEnergy());
  values.push_back(system_.lastIterations());
}

ModuleEntry rigidModuleEntry() {
  return {"bodies", &rigidSchema, [](const SceneConfig& section, SimulationContext&) {
            std::vector<std::unique_ptr<Module>> v;
            v.push_back(std::make_unique<RigidModule>(readRigidOptions(section)));
            return v;
          }};
}

void RigidModule::saveState(io::StateWriter& w) const {
  io::StateWriter system = w.sub("system");
  system_.saveState(system);
  w.putReal("energy0", energy0_);
  w.putReal("maxEnergyDrift", maxEnergyDrift_);
}

void RigidModule::loadState(const io::StateReader& r) {
  system_.loadState(r.sub("system"));
  energy0_ = r.real("energy0");
  maxEnergyDrift_ = r.real("maxEnergyDrift");
}

}  // namespace mfsi
