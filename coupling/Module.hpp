#pragma once
/// \file
/// \brief A physics module of a run (fluid, a membrane, the rigid frames, the FSI coupling).
///
/// Design rationale: which physics a run simulates is decided by the scene at run time — a scene
/// names its effects, and a module it does not name must never be constructed (it allocates
/// nothing, launches no kernel, costs nothing). So modules are created on demand from a catalogue
/// of (scene section -> factory), and the driver talks to them through this small host-side
/// interface. Virtual calls happen once per step on the host, never inside kernels.
#include "core/Fields.hpp"
#include "core/MeshGeometry.hpp"
#include "core/SceneConfig.hpp"
#include "core/Timers.hpp"
#include "core/io/Checkpoint.hpp"
#include "core/io/FieldOutput.hpp"
#include "core/parallel/Halo.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace mfsi {

/// \brief What a module may use while it is built and run.
struct SimulationContext {
  HexMesh* mesh = nullptr;  ///< null when the scene has no `mesh` section
  MeshGeometry* geometry = nullptr;
  /// On several ranks: `mesh` is this rank's part and this names the others (null: one rank).
  const RankDomain* domain = nullptr;
  Timers* timers = nullptr;
  /// The modules built so far: a module that composes others (the coupling) takes them from here.
  std::vector<std::unique_ptr<class Module>>* built = nullptr;
};

/// \brief Where a run's output starts: a new run at step 0, or a run restarted from a checkpoint
/// at `step` that continues the files of the run in the same folder (`continueFiles`: keep their
/// rows up to `step`, drop the later ones) or starts new ones in another folder.
struct OutputStart {
  long long step = 0;
  bool continueFiles = false;
  /// The step the folder's files begin after (0, or the step of the checkpoint a run was
  /// restarted from into a new folder): a continued file keeps its rows of steps firstStep+1 .. step.
  long long firstStep = 0;
};

class Module {
 public:
  explicit Module(std::string name);
  virtual ~Module() = default;
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;

  const std::string& name() const { return name_; }
  /// Advance over [t.time, t.time + t.dt]. Throws DivergenceError when the solution is lost.
  virtual void advance(const TimeState& t) = 0;
  /// True when this module solves a steady problem and its last step found it converged (its
  /// residuals below its tolerance): a run whose modules all say so has nothing left to do.
  virtual bool steadyStateReached() const { return false; }
  /// True when this module solves a steady problem (its steps are iterations towards one state).
  virtual bool solvesSteadyState() const { return false; }
  /// For a steady module that has not reached its steady state: what is still off (residuals
  /// against their tolerance), for the run's message.
  virtual std::string steadyStateGap() const { return ""; }
  /// Named summary numbers for summary.json ("<module>.<what>").
  virtual void addMetrics(std::map<std::string, double>& /*metrics*/) const {}
  /// Open the module's own output files in the run's output folder (before the first step).
  virtual void openOutput(const std::string& /*dir*/, const OutputStart& /*start*/) {}
  /// Add this module's fields to an output frame: a grid of its own (a membrane, the bodies) or
  /// fields on another's (the fluid's U and p on the scene mesh's grid "mesh").
  virtual void addOutputFields(io::FieldFrame& /*frame*/) {}
  /// Column names and values of this module in steps.csv.
  virtual std::vector<std::string> stepColumns() const { return {}; }
  virtual void appendStepValues(std::vector<double>& /*values*/) const {}
  /// Write everything this module needs to continue the run *bitwise* from the end of the last
  /// completed step (fields, old time levels, solver guesses and caches that a step reads).
  virtual void saveState(io::StateWriter& w) const = 0;
  /// Read back what saveState wrote, into a module built from the same scene. Throws InputError
  /// (naming the checkpoint and dataset) when the checkpoint does not fit this module.
  virtual void loadState(const io::StateReader& r) = 0;
  /// Modules this one owns and advances itself (the coupling's fluid and membranes): the driver
  /// asks them for output, columns and metrics, but never advances them.
  virtual std::vector<Module*> parts() { return {}; }

  /// How many modules of each name were ever constructed in this process (for tests of the
  /// "a module the scene does not name costs nothing" rule).
  static const std::map<std::string, int>& constructionCounts();

 private:
  std::string name_;
};

/// \brief One entry of the module catalogue: the scene section that switches the module on, the
/// schema of that section, and the factory.
struct ModuleEntry {
  std::string section;
  std::function<Schema()> schema;
  std::function<std::vector<std::unique_ptr<Module>>(const SceneConfig& section, SimulationContext& ctx)> create;
};

/// Every module the code knows, in construction order.
const std::vector<ModuleEntry>& moduleCatalogue();

}  // namespace mfsi
