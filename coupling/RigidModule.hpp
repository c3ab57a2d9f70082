#pragma once
/// \file
/// \brief The `bodies` section as a module of a run: rigid frames on joints and restraints.
#include "core/RunLog.hpp"
#include "coupling/Module.hpp"
#include "structure/rigid/RigidBodySystem.hpp"

#include <string>

namespace mfsi {

class RigidModule final : public Module {
 public:
  explicit RigidModule(const RigidSystemOptions& options);
  void advance(const TimeState& t) override;
  /// The system's state (RigidBodySystem::saveState) under "system", the energy at the start and
  /// the largest energy drift so far.
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  void addMetrics(std::map<std::string, double>& metrics) const override;
  /// The grid "bodies": one point per body at its centre of mass, with its velocity, angular
  /// velocity, (roll, pitch, yaw), force and moment.
  void addOutputFields(io::FieldFrame& frame) override;
  /// bodies.csv: a header, then one row per body at set-up and after every committed step. A run
  /// restarted into a new folder starts a new file with the rows of the checkpoint's state; one that
  /// continues the files keeps the header and the nBodies (start.step - start.firstStep + 1) rows
  /// up to the checkpoint and appends. Throws OutputError (disk full) or InputError (the file to
  /// continue does not fit).
  void openOutput(const std::string& dir, const OutputStart& start) override;
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;

  RigidBodySystem& system() { return system_; }
  /// After a committed step (advance, or the coupling's commit): energy drift and bodies.csv.
  void recordStep();

 private:
  /// Append the rows of the latest state to bodies.csv in one write; OutputError when it fails
  /// (the file then keeps the whole rows before them).
  void writeRows();

  RigidBodySystem system_;
  AppendFile csv_;  ///< bodies.csv
  double energy0_ = 0.0;
  double maxEnergyDrift_ = 0.0;
};

/// Catalogue entry of the `bodies` section.
ModuleEntry rigidModuleEntry();

}  // namespace mfsi
