#pragma once
/// \file
/// \brief The run driver: builds the mesh and exactly the modules a scene names, then steps them.
#include "coupling/Module.hpp"
#include "core/RunLog.hpp"

namespace mfsi {

/// Schema of a whole scene: name, description, mesh, time, and one section per catalogued module.
Schema sceneSchema();

/// \brief Time stepping of the `time` section.
struct TimeOptions {
  real endTime = 0.0;  ///< 0: no time stepping (a mesh-only scene)
  real dt = 0.0;
  int maxSteps = 0;  ///< 0: as many as endTime/dt needs
};

/// \brief When fields are written (`output.fields`).
struct FieldOutputOptions {
  real interval = 0.0;  ///< simulated time between frames (0: not by time)
  int everySteps = 0;   ///< steps between frames (0: not by steps)
  bool initial = false;  ///< a frame of the start state
  bool final = true;     ///< a frame of the end state
};

/// \brief What `Simulation::run` reports back.
struct RunResult {
  long long steps = 0;
  double simTime = 0.0;
  std::map<std::string, double> metrics;
};

class Simulation {
 public:
  /// Build the mesh and the modules the scene names. Throws InputError on bad input.
  explicit Simulation(const SceneConfig& scene);

  /// Step to the end time, writing steps.csv into `outDir` and drawing progress.
  RunResult run(const std::string& outDir, bool terminal);

  /// True when the scene has a `mesh` section (a rigid-only or membrane-only scene has none).
  bool hasMesh() const { return hasMesh_; }
  const HexMesh& mesh() const { return mesh_; }
  const std::vector<std::unique_ptr<Module>>& modules() const { return modules_; }
  Timers& timers() { return timers_; }
  const TimeOptions& timeOptions() const { return time_; }
  /// Steps completed and the time they reached, also when `run` stopped with an exception (a
  /// diverged run reports how far it got).
  long long completedSteps() const { return completedSteps_; }
  double completedTime() const { return completedTime_; }

 private:
  void meshMetrics(std::map<std::string, double>& m) const;
  /// The state now, as one output frame: the scene mesh's grid "mesh" (positions, displacement
  /// from the reference mesh, each cell's scaled Jacobian) and every module's fields.
  io::FieldFrame fieldFrame(double time, long long step);

  Timers timers_;
  bool hasMesh_ = false;
  HexMesh mesh_;
  MeshGeometry geometry_;
  TimeOptions time_;
  long long nSteps_ = 0;  ///< from time_ (checked at set-up)
  FieldOutputOptions fieldOutput_;
  std::vector<std::unique_ptr<Module>> modules_;  ///< advanced by the driver
  std::vector<Module*> reporting_;                ///< modules_ and their parts: output, columns, metrics
  long long completedSteps_ = 0;
  double completedTime_ = 0;
};

}  // namespace mfsi
