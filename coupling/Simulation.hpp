#pragma once
/// \file
/// \brief The run driver: builds the mesh and exactly the modules a scene names, then steps them.
#include "coupling/Module.hpp"
#include "core/RunLog.hpp"
#include "core/io/Redistribute.hpp"

#include <cstdint>
#include <optional>

namespace mfsi {

/// Schema of a whole scene: name, description, mesh, time, and one section per catalogued module.
Schema sceneSchema();

/// \brief Time stepping of the `time` section.
struct TimeOptions {
  real endTime = 0.0;  ///< 0: no time stepping (a mesh-only scene)
  real dt = 0.0;
  int maxSteps = 0;  ///< 0: as many as endTime/dt needs
  bool stopAtSteadyState = true;  ///< end when every module reached its steady state
};

/// \brief When fields are written (`output.fields`).
struct FieldOutputOptions {
  real interval = 0.0;  ///< simulated time between frames (0: not by time)
  int everySteps = 0;   ///< steps between frames (0: not by steps)
  bool initial = false;  ///< a frame of the start state
  bool final = true;     ///< a frame of the end state
};

/// \brief When checkpoints are written (`output.checkpoint`).
struct CheckpointOptions {
  int everySteps = 0;       ///< a checkpoint every this many steps (0: not by steps)
  double wallSeconds = 0;   ///< a checkpoint every this much wall-clock time (0: not by time)
  int keep = 2;             ///< the most recent checkpoints kept (older ones are removed)
  bool final = false;       ///< a checkpoint at the end of the run
};

/// \brief What `Simulation::run` reports back.
struct RunResult {
  long long steps = 0;
  double simTime = 0.0;
  std::map<std::string, double> metrics;
  /// SIGINT or SIGTERM stopped the run after `steps` (a checkpoint of that state was written).
  int interruptedBy = 0;
  std::string lastCheckpoint;  ///< path of the last checkpoint written ("" if none)
  /// Every module reached its steady state (Module::steadyStateReached) after `steps`: the run
  /// stopped there, before time.endTime.
  bool steadyStateReached = false;
  /// The run asked to stop at its steady state (time.stopAtSteadyState) and has steady modules,
  /// but reached time.endTime / maxSteps first: what is off ("" when nothing is).
  std::string steadyStateMissed;
};

/// \brief What a decomposition keeps on one rank (the seed's singleProcessorFaceSets): the cells
/// along every membrane a scene cuts from its mesh (the owners of its wall patch's faces) and
/// along every baffle of the mesh, a membrane or a fixed wall (the owners of its faces, both
/// sides: a baffle face is one face of two cells, and a rank holds it only with both). One group
/// per membrane or baffle; `names` (optional) receives what each group is, for messages.
std::vector<std::vector<lid_t>> cellGroupsKeptTogether(const SceneConfig& scene, const HexMesh& mesh,
                                                       std::vector<std::string>* names = nullptr);

class Simulation {
 public:
  /// Build the mesh and the modules the scene names. Throws InputError on bad input.
  explicit Simulation(const SceneConfig& scene);
  /// \brief The same with the decomposition over several ranks read from `partitionFile` (as
  /// `mfsi partition` writes it) instead of computed; empty: computed (METIS).
  Simulation(const SceneConfig& scene, const std::string& partitionFile);

  /// Step to the end time, writing steps.csv into `outDir` and drawing progress. After `restore`,
  /// from the checkpoint's step on; `continueFiles`: into the folder of the run that wrote the
  /// checkpoint, continuing its steps.csv, module files and field index (else new files).
  /// SIGINT/SIGTERM (installInterruptHandlers) end the run after the current step with a
  /// checkpoint (RunResult::interruptedBy).
  RunResult run(const std::string& outDir, bool terminal, bool continueFiles = false);

  /// Put the run into the state a checkpoint holds, bitwise. The scene may differ from the one
  /// that wrote the checkpoint in time.endTime, time.maxSteps, output, name and description
  /// alone; anything else is refused with the list of changes. With `allowChanges` the other
  /// settings may change too (to go on from a diverged run's last good state with other solver
  /// settings: the run then no longer repeats one that was not stopped), but not the mesh nor
  /// time.dt; the changes accepted are returned. Throws InputError.
  std::vector<std::string> restore(const std::string& checkpointFile, bool allowChanges = false);
  /// The checkpoint to continue a run from: `path` itself (a file), or the latest checkpoint in
  /// `<path>/checkpoints/`. Throws InputError when there is none.
  static std::string findCheckpoint(const std::string& path);
  /// The run folder a checkpoint file belongs to (the parent of its `checkpoints/` folder).
  static std::string runFolderOf(const std::string& checkpointFile);

  /// True when the scene has a `mesh` section (a rigid-only or membrane-only scene has none).
  bool hasMesh() const { return hasMesh_; }
  /// Ranks of MPI_COMM_WORLD the run is decomposed over (1: the whole mesh here), and this one.
  int ranks() const { return ranks_; }
  int rank() const { return rank_; }
  /// The scene's whole mesh: on one rank the mesh the run moves; on several, empty (rank 0 reads
  /// it and frees it once it has handed out the parts; meshCounts() holds its sizes).
  const HexMesh& mesh() const { return mesh_; }
  /// The sizes of the whole mesh, on every rank.
  const MeshCounts& meshCounts() const { return counts_; }
  const std::vector<std::unique_ptr<Module>>& modules() const { return modules_; }
  Timers& timers() { return timers_; }
  const TimeOptions& timeOptions() const { return time_; }
  /// Steps completed and the time they reached, also when `run` stopped with an exception (a
  /// diverged run reports how far it got).
  long long completedSteps() const { return completedSteps_; }
  double completedTime() const { return completedTime_; }
  /// After restore(): the ranks of the run that wrote the checkpoint, when its decomposition was
  /// not this run's (the state was carried across, core/io/Redistribute); 0 otherwise.
  int carriedFromRanks() const { return carriedFromRanks_; }
  /// Path of the last checkpoint this run wrote ("" if none): where a diverged run can go back to.
  const std::string& lastCheckpoint() const { return lastCheckpoint_; }

 private:
  void meshMetrics(std::map<std::string, double>& m) const;
  /// Write `<outDir>/checkpoints/checkpoint_<step>.h5` and remove the ones beyond `keep`. On
  /// several ranks rank 0 writes that file (the run, the whole mesh's points, its modules) and
  /// rank r > 0 its modules' state to `checkpoint_<step>.rank<r>.h5`; rank 0's file is committed
  /// last, once every rank has committed its own, so a checkpoint that a listing finds is whole.
  std::string writeCheckpoint(const std::string& outDir, const TimeState& ts, const io::FieldSeries& fields,
                              double nextFrameTime, long long lastFrameStep, double wallSeconds);
  /// This rank's part of a checkpoint written on another decomposition (`writtenOn` ranks, its
  /// rank 0's file already open as `first`), carried into a file in memory (core/io/Redistribute).
  io::Hdf5File carryCheckpoint(const io::Hdf5File& first, const std::string& checkpointFile, int writtenOn);
  /// The state now, as one output frame: the scene mesh's grid "mesh" (positions, displacement
  /// from the reference mesh, each cell's scaled Jacobian) and every module's fields.
  io::FieldFrame fieldFrame(double time, long long step);
  /// The scene mesh's grid of a frame; on several ranks this rank's part (its owned points and cells).
  io::OutputGrid meshGrid() const;

  /// Build this rank's part of the mesh: rank 0 partitions the mesh it read (METIS over the ranks,
  /// each membrane's cells on one rank, or the partition file) and sends every rank its part;
  /// throws InputError (on every rank) for what does not run on several ranks yet.
  void decompose(const SceneConfig& scene, const std::string& partitionFile);
  /// Rank 0: the rank of every cell of mesh_.
  std::vector<int> partitionCells(const SceneConfig& scene, const std::string& partitionFile) const;
  /// The mesh this rank computes on and its geometry: its part on several ranks, else the whole mesh.
  HexMesh& ownMesh() { return ranks_ > 1 ? localMesh_ : mesh_; }
  const HexMesh& ownMesh() const { return ranks_ > 1 ? localMesh_ : mesh_; }
  MeshGeometry& ownGeometry() { return ranks_ > 1 ? localGeometry_ : geometry_; }
  const MeshGeometry& ownGeometry() const { return ranks_ > 1 ? localGeometry_ : geometry_; }
  /// The moved points from a checkpoint: `first` is rank 0's file, `states` this rank's part of
  /// the state (its own file, or one carried from another decomposition).
  void restorePoints(const io::Hdf5File& first, const io::Hdf5File& states);

  Timers timers_;
  bool hasMesh_ = false;
  HexMesh mesh_;  ///< the whole mesh (on several ranks: rank 0's while it hands out the parts, then empty)
  MeshCounts counts_;  ///< the whole mesh's sizes, on every rank
  MeshGeometry geometry_;
  /// On several ranks: this rank's part of mesh_, its geometry, and the ranks it talks to.
  int ranks_ = 1, rank_ = 0;
  HexMesh localMesh_;
  MeshGeometry localGeometry_;
  RankDomain domain_;
  int carriedFromRanks_ = 0;
  /// Several ranks: this rank's global ids, as its checkpoints record them (made at the first one).
  std::optional<io::PartIds> partIds_;
  std::vector<std::int64_t> partFaces_;  ///< several ranks: the global face of each of the part's faces
  std::int64_t partitionHash_ = 0;  ///< several ranks: a hash of the cell -> rank map (checkpoints hold it)
  TimeOptions time_;
  long long nSteps_ = 0;  ///< from time_ (checked at set-up)
  FieldOutputOptions fieldOutput_;
  CheckpointOptions checkpoint_;
  std::string sceneText_;  ///< the resolved scene, kept in checkpoints to compare on restart
  /// Where a restored run starts (restore()).
  struct StartState {
    bool restored = false;
    TimeState time;
    double nextFrameTime = 0;
    long long lastFrameStep = -1;
    std::string fields;   ///< FieldSeries::state() of the run that wrote the checkpoint
    double wallSeconds = 0;  ///< wall time of the steps before the checkpoint
    long long firstStep = 0;  ///< OutputStart::firstStep of the run that wrote it
  };
  StartState start_;
  long long firstStep_ = 0;  ///< OutputStart::firstStep of this run's files
  std::vector<std::unique_ptr<Module>> modules_;  ///< advanced by the driver
  std::vector<Module*> reporting_;                ///< modules_ and their parts: output, columns, metrics
  long long completedSteps_ = 0;
  double completedTime_ = 0;
  std::string lastCheckpoint_;
};

}  // namespace mfsi
