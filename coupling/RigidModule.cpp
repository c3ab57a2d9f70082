#include "coupling/RigidModule.hpp"

#include "structure/rigid/RigidConfig.hpp"

#include <cmath>

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
  if (csv_.is_open()) system_.writeCsvRows(csv_);
}

void RigidModule::addMetrics(std::map<std::string, double>& metrics) const {
  for (const auto& [k, v] : system_.metrics()) metrics["bodies." + k] = v;
  metrics["bodies.maxEnergyDrift"] = maxEnergyDrift_;
}

void RigidModule::openOutput(const std::string& dir) {
  csv_.open(dir + "/bodies.csv");
  RigidBodySystem::writeCsvHeader(csv_);
  system_.writeCsvRows(csv_);
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

}  // namespace mfsi
