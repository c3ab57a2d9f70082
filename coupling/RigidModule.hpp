#pragma once
/// \file
/// \brief The `bodies` section as a module of a run: rigid frames on joints and restraints.
#include "coupling/Module.hpp"
#include "structure/rigid/RigidBodySystem.hpp"

#include <fstream>

namespace mfsi {

class RigidModule final : public Module {
 public:
  explicit RigidModule(const RigidSystemOptions& options);
  void advance(const TimeState& t) override;
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  void addMetrics(std::map<std::string, double>& metrics) const override;
  /// The grid "bodies": one point per body at its centre of mass, with its velocity, angular
  /// velocity, (roll, pitch, yaw), force and moment.
  void addOutputFields(io::FieldFrame& frame) override;
  void openOutput(const std::string& dir, const OutputStart& start) override;
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;

  RigidBodySystem& system() { return system_; }
  /// After a committed step (advance, or the coupling's commit): energy drift and bodies.csv.
  void recordStep();

 private:
  RigidBodySystem system_;
  std::ofstream csv_;
  double energy0_ = 0.0;
  double maxEnergyDrift_ = 0.0;
};

/// Catalogue entry of the `bodies` section.
ModuleEntry rigidModuleEntry();

}  // namespace mfsi
