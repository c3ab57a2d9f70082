#include "coupling/Simulation.hpp"

#include "core/Interrupt.hpp"
#include "core/MeshConfig.hpp"
#include "core/io/HostCopy.hpp"
#include "core/parallel/FailureAgreement.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/MeshScatter.hpp"
#include "core/parallel/Partition.hpp"
#include "kernels/Blas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>

namespace mfsi {

namespace fs = std::filesystem;

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
                       .key("maxSteps", Schema::integer("stop after this many steps (0: no limit)").atLeast(0), Default(0))
                       .key("stopAtSteadyState",
                            Schema::boolean("end the run after the step in which every module has reached its "
                                            "steady state (a steady fluid whose residuals fell below "
                                            "fluid.pimple.outerTolerance)"),
                            Default(true)),
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
                    Presence::Optional)
               .key("checkpoint",
                    Schema::map("checkpoints to continue the run from (mfsi run --restart RUN_DIR): "
                                "checkpoints/checkpoint_<step>.h5; SIGINT and SIGTERM always write one")
                        .key("everySteps", Schema::integer("a checkpoint every this many steps (0: not by steps)")
                                               .atLeast(0), Default(0))
                        .key("wallSeconds", Schema::real("a checkpoint every this much wall-clock time (0: not by "
                                                         "time)", "s").atLeast(0), Default(0.0))
                        .key("keep", Schema::integer("the most recent checkpoints kept").atLeast(1), Default(2))
                        .key("final", Schema::boolean("a checkpoint at the end of the run"), Default(false)),
                    Presence::Optional),
           Presence::Optional);
  for (const auto& entry : moduleCatalogue()) s.key(entry.section, entry.schema(), Presence::OptionalSection);
  return s;
}

Simulation::Simulation(const SceneConfig& scene) : Simulation(scene, std::string()) {}

Simulation::Simulation(const SceneConfig& scene, const std::string& partitionFile) {
  hasMesh_ = scene.has("mesh");
  int mpiUp = 0;
  MPI_Initialized(&mpiUp);
  if (mpiUp) {
    MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  }
  if (hasMesh_) {
    ScopedTimer t(timers_, "mesh");
    if (ranks_ > 1) {  // rank 0 alone reads the mesh; decompose() hands out the parts
      runOnOneRank(MPI_COMM_WORLD, 0, [&] {
        mesh_ = buildMesh(scene.child("mesh"));
        counts_ = MeshCounts::of(mesh_);
      });
      MPI_Bcast(&counts_, sizeof(MeshCounts), MPI_BYTE, 0, MPI_COMM_WORLD);
    } else {
      mesh_ = buildMesh(scene.child("mesh"));
      counts_ = MeshCounts::of(mesh_);
      geometry_ = allocateGeometry(mesh_);
      computeGeometry(ExecSpace(), mesh_, geometry_);
      Kokkos::fence();
    }
  }
  time_.endTime = scene.get<double>("time.endTime");
  time_.dt = scene.get<double>("time.dt");
  time_.maxSteps = scene.get<int>("time.maxSteps");
  time_.stopAtSteadyState = scene.get<bool>("time.stopAtSteadyState");
  fieldOutput_.interval = scene.get<double>("output.fields.interval");
  fieldOutput_.everySteps = scene.get<int>("output.fields.everySteps");
  fieldOutput_.initial = scene.get<bool>("output.fields.initial");
  fieldOutput_.final = scene.get<bool>("output.fields.final");
  checkpoint_.everySteps = scene.get<int>("output.checkpoint.everySteps");
  checkpoint_.wallSeconds = scene.get<double>("output.checkpoint.wallSeconds");
  checkpoint_.keep = scene.get<int>("output.checkpoint.keep");
  checkpoint_.final = scene.get<bool>("output.checkpoint.final");
  sceneText_ = scene.resolvedYaml(false);
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

  if (ranks_ > 1) decompose(scene, partitionFile);
  else if (!partitionFile.empty() && hasMesh_)  // checked all the same: a map for more ranks is a mistake
    readPartitionMap(partitionFile, static_cast<std::size_t>(mesh_.nCells()), 1);

  SimulationContext ctx;
  if (hasMesh_) {
    ctx.mesh = &ownMesh();
    ctx.geometry = &ownGeometry();
    if (ranks_ > 1) ctx.domain = &domain_;
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

std::vector<std::vector<lid_t>> cellGroupsKeptTogether(const SceneConfig& scene, const HexMesh& mesh,
                                                       std::vector<std::string>* names) {
  std::vector<std::vector<lid_t>> groups;
  auto owner = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto add = [&](const std::vector<int>& patches, const std::string& what) {
    std::vector<lid_t> cells;
    for (int p : patches) {
      const auto& patch = mesh.patches()[p];
      for (lid_t f = patch.start; f < patch.start + patch.size; ++f) cells.push_back(owner(f));
    }
    if (cells.empty()) return;
    groups.push_back(std::move(cells));
    if (names) names->push_back(what);
  };
  const auto& patches = mesh.patches();
  for (std::size_t p = 0; p < patches.size(); ++p)
    if (patches[p].kind == PatchKind::BaffleMaster)
      add({static_cast<int>(p), patches[p].pairedPatch},
          "baffle '" + patches[p].name.substr(0, patches[p].name.rfind("_master")) + "'");
  if (!scene.has("membranes")) return groups;
  for (std::size_t i = 0; i < scene.size("membranes"); ++i) {
    const std::string m = "membranes." + std::to_string(i) + ".mesh.boundaryPatch.patch";
    if (!scene.has(m)) continue;  // a baffle membrane: its baffle's group above
    const std::string name = scene.get<std::string>(m);
    const int p = mesh.findPatch(name);
    if (p >= 0) add({p}, "membrane patch '" + name + "'");  // else the membrane's set-up names it
  }
  return groups;
}

void Simulation::decompose(const SceneConfig& scene, const std::string& partitionFile) {
  // What runs on several ranks: the fluid on the parts of the scene mesh, membranes cut from it
  // and rigid bodies (each solved by every rank on the same gathered loads), the coupling and the
  // mesh motion, the field output, reports and checkpoints (one file per rank).
  const std::string how = " (run it on one rank: without mpirun, or mpirun -np 1; threads: --threads)";
  if (!hasMesh_) throw InputError(scene.where(), "a scene without a mesh runs on one rank" + how);
  ScopedTimer t(timers_, "decompose");
  // Rank 0 partitions the mesh it read, and sends every rank its part.
  std::vector<int> cellRank;
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the map
  {
    ScopedTimer tp(timers_, "decompose.partition");
    runOnOneRank(MPI_COMM_WORLD, 0, [&] {
      cellRank = partitionCells(scene, partitionFile);
      for (int r : cellRank) hash = (hash ^ static_cast<std::uint64_t>(r)) * 1099511628211ull;
    });
    MPI_Bcast(&hash, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  }
  partitionHash_ = static_cast<std::int64_t>(hash >> 1);
  const HexMesh* whole = rank_ == 0 ? &mesh_ : nullptr;
  {
    ScopedTimer ts(timers_, "decompose.scatter");
    const LocalMeshPart lp = scatterParts(MPI_COMM_WORLD, 0, whole, cellRank);
    localMesh_ = buildHexMesh(lp.input);
    domain_.comm = MPI_COMM_WORLD;
    domain_.cells = lp.cells;
    domain_.nodes = lp.nodes;
    domain_.incompleteNode = lp.incompleteNode;
  }
  localGeometry_ = allocateGeometry(localMesh_);
  computeGeometry(ExecSpace(), localMesh_, localGeometry_);
  {
    ScopedTimer tf(timers_, "decompose.faceIds");
    partFaces_ = globalFaceIdsFromRoot(MPI_COMM_WORLD, 0, localMesh_, whole);
  }
  mesh_ = HexMesh();  // rank 0's whole mesh is not needed past this point
  Kokkos::fence();
}

std::vector<int> Simulation::partitionCells(const SceneConfig& scene, const std::string& partitionFile) const {
  Partition part;
  if (partitionFile.empty()) {
    PartitionOptions opt;
    opt.parts = ranks_;
    opt.keepTogether = cellGroupsKeptTogether(scene, mesh_);
    part = partitionGraph(cellDualGraph(mesh_), opt);
  } else {
    part.cellRank = readPartitionMap(partitionFile, static_cast<std::size_t>(mesh_.nCells()), ranks_);
    std::vector<std::string> names;
    const auto groups = cellGroupsKeptTogether(scene, mesh_, &names);
    for (std::size_t g = 0; g < groups.size(); ++g)
      for (lid_t c : groups[g])
        if (part.cellRank[c] != part.cellRank[groups[g][0]])
          throw InputError(partitionFile + ": the cells along " + names[g] + " are on ranks " +
                           std::to_string(part.cellRank[groups[g][0]]) + " (cell " + std::to_string(groups[g][0]) +
                           ") and " + std::to_string(part.cellRank[c]) + " (cell " + std::to_string(c) +
                           "); a membrane's or a baffle's cells stay on one rank (mfsi partition writes such a map)");
  }
  return part.cellRank;
}

void Simulation::meshMetrics(std::map<std::string, double>& m) const {
  if (!hasMesh_) return;
  // The mesh may have moved since set-up. On several ranks each measures its part (its owned
  // cells, each face once) and the parts are combined: nothing is gathered.
  computeGeometry(ExecSpace(), ownMesh(), ownGeometry());
  MeshQuality q = computeQuality(ExecSpace(), ownMesh(), ownGeometry());
  if (ranks_ > 1) {  // through the solvers' communicator: sums in rank order, the same bits every run
    const SolverComm comm(MPI_COMM_WORLD, nullptr);
    q.minScaledJacobian = -comm.globalMax(-q.minScaledJacobian);
    q.minVolume = -comm.globalMax(-q.minVolume);
    q.maxNonOrthogonality = comm.globalMax(q.maxNonOrthogonality);
    q.maxSkewness = comm.globalMax(q.maxSkewness);
    q.maxVolume = comm.globalMax(q.maxVolume);
    double sum[3] = {q.totalVolume, q.meanNonOrthogonality * static_cast<double>(q.countedFaces),
                     static_cast<double>(q.countedFaces)};
    comm.globalSum(sum, 3);
    q.totalVolume = sum[0];
    q.meanNonOrthogonality = sum[2] > 0 ? sum[1] / sum[2] : 0.0;
  }
  m["mesh.min_scaled_jacobian"] = q.minScaledJacobian;
  m["mesh.max_non_orthogonality_deg"] = q.maxNonOrthogonality;
  m["mesh.mean_non_orthogonality_deg"] = q.meanNonOrthogonality;
  m["mesh.max_skewness"] = q.maxSkewness;
  m["mesh.total_volume"] = q.totalVolume;
  m["mesh.min_cell_volume"] = q.minVolume;
  m["mesh.max_cell_volume"] = q.maxVolume;
  m["mesh.internal_faces"] = static_cast<double>(counts_.internalFaces);
  m["mesh.boundary_faces"] = static_cast<double>(counts_.boundaryFaces);
  m["mesh.patches"] = static_cast<double>(counts_.patches);
}

io::OutputGrid Simulation::meshGrid() const {
  // On several ranks this rank's part (its owned points and cells, by global id), else the mesh.
  const bool decomposed = ranks_ > 1;
  const HexMesh& m = ownMesh();
  io::OutputGrid g;
  g.name = "mesh";
  g.shape = io::CellShape::Hexahedron;
  g.decomposed = decomposed;
  g.globalPoints = static_cast<std::size_t>(counts_.nodes);
  g.globalCells = static_cast<std::size_t>(counts_.cells);
  const std::size_t nNodes = static_cast<std::size_t>(m.nOwnedNodes());
  const std::size_t nCells = static_cast<std::size_t>(m.nOwnedCells());
  auto nodeIds = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodeGlobalIds());  // the identity on one rank
  if (decomposed) {
    auto cellIds = Kokkos::create_mirror_view_and_copy(HostSpace(), m.cellGlobalIds());
    g.pointRows.assign(nodeIds.data(), nodeIds.data() + nNodes);
    g.cellRows.assign(cellIds.data(), cellIds.data() + nCells);
  }
  g.points = io::hostValues(m.points(), nNodes);
  const std::vector<double> x0 = io::hostValues(m.referencePoints(), nNodes);
  std::vector<double> d(g.points.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = g.points[i] - x0[i];
  for (double c : io::hostValues(m.cellNodes(), nCells))
    g.cells.push_back(static_cast<std::int64_t>(nodeIds(static_cast<std::size_t>(c))));  // global points
  RealView quality("mfsi::output::scaledJacobian", static_cast<std::size_t>(m.nCells()));
  cellScaledJacobians(ExecSpace(), m, quality);
  g.addPointField("meshDisplacement", 3, std::move(d), true, true);
  g.addCellField("scaledJacobian", 1, io::hostValues(quality, nCells), true, true);
  return g;
}

io::FieldFrame Simulation::fieldFrame(double time, long long step) {
  io::FieldFrame frame;
  frame.time = time;
  frame.step = step;
  if (hasMesh_) frame.grids.push_back(meshGrid());  // on several ranks each writes its own part
  // Parts first, then the module that owns them (the coupling moves a mounted membrane's grid to
  // where its frames carry it).
  for (auto& m : modules_) {
    for (Module* p : m->parts()) p->addOutputFields(frame);
    m->addOutputFields(frame);
  }
  return frame;
}

RunResult Simulation::run(const std::string& outDir, bool terminal, bool continueFiles) {
  RunResult r;
  const long long nSteps = nSteps_;
  continueFiles = continueFiles && start_.restored;
  TimeState ts;
  if (start_.restored) ts = start_.time;
  ts.endTime = time_.endTime;
  firstStep_ = continueFiles ? start_.firstStep : ts.step;
  std::vector<std::string> columns = {"step", "time", "wall_s"};
  for (const Module* m : reporting_)
    for (const auto& c : m->stepColumns()) columns.push_back(m->name() + "." + c);
  // On several ranks rank 0 writes every file; the others take part in what the rows and frames
  // gather (probes, forces, fields) and write nothing.
  const bool writer = rank_ == 0;
  StepLog log;
  if (writer)
    log = continueFiles ? StepLog(outDir + "/steps.csv", columns, ts.step - firstStep_)
                        : StepLog(outDir + "/steps.csv", columns);
  const OutputStart outputStart{ts.step, continueFiles, firstStep_};
  if (writer)
    for (Module* m : reporting_) m->openOutput(outDir, outputStart);
  Progress progress(nSteps, time_.endTime, terminal, writer ? 0 : -1);
  io::FieldSeries fields(outDir, ranks_ > 1 ? MPI_COMM_WORLD : MPI_COMM_NULL);
  if (continueFiles) fields.restore(start_.fields, ts.step);
  long long lastFrameStep = start_.restored ? start_.lastFrameStep : -1;
  auto writeFrame = [&] {
    ScopedTimer t(timers_, "output");
    io::FieldFrame frame = fieldFrame(ts.time, ts.step);
    fields.write(frame);  // collective on several ranks
    lastFrameStep = ts.step;
  };
  double nextFrameTime = start_.restored ? start_.nextFrameTime : fieldOutput_.interval;
  if (fieldOutput_.initial && !start_.restored) writeFrame();
  // wall_s and checkpoints count the wall time of the steps before a restart too.
  const double start = wallSeconds() - start_.wallSeconds;
  double lastCheckpointWall = wallSeconds();
  long long lastCheckpointStep = start_.restored ? ts.step : -1;
  auto checkpoint = [&] {
    ScopedTimer t(timers_, "checkpoint");
    r.lastCheckpoint = writeCheckpoint(outDir, ts, fields, nextFrameTime, lastFrameStep, wallSeconds() - start);
    lastCheckpoint_ = r.lastCheckpoint;
    lastCheckpointWall = wallSeconds();
    lastCheckpointStep = ts.step;
  };
  for (long long s = ts.step; s < nSteps; ++s) {
    ts.dtOld = ts.step > 0 ? ts.dt : time_.dt;
    // The last step ends at endTime; a remainder short of dt by round-off alone (time summed
    // step by step) is a full step, not a step of 0.0199999... that a variable-step scheme would see.
    const double rest = time_.endTime - ts.time;
    ts.dt = rest < time_.dt * (1 - 1e-9) ? rest : time_.dt;
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
    if (writer) log.row(row);
    bool frame = fieldOutput_.everySteps > 0 && ts.step % fieldOutput_.everySteps == 0;
    if (fieldOutput_.interval > 0 && ts.time >= nextFrameTime - 1e-9 * ts.dt) {
      frame = true;
      while (nextFrameTime <= ts.time + 1e-9 * ts.dt) nextFrameTime += fieldOutput_.interval;
    }
    if (frame) writeFrame();
    progress.update(ts.step, ts.time);
    int signal = interruptSignal();
    if (ranks_ > 1) {  // every rank stops after the same step
      int any = 0;
      MPI_Allreduce(&signal, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
      signal = any;
    }
    if (signal != 0) {
      r.interruptedBy = signal;
      break;
    }
    const bool byStep = checkpoint_.everySteps > 0 && ts.step % checkpoint_.everySteps == 0;
    const bool byWall = checkpoint_.wallSeconds > 0 && wallSeconds() - lastCheckpointWall >= checkpoint_.wallSeconds;
    if (byStep || byWall) checkpoint();
    if (time_.stopAtSteadyState && ts.step < nSteps && std::all_of(modules_.begin(), modules_.end(),
                                        [](const auto& m) { return m->steadyStateReached(); })) {
      r.steadyStateReached = true;
      break;
    }
  }
  if (time_.stopAtSteadyState && !r.steadyStateReached && r.interruptedBy == 0)
    for (const auto& m : modules_)
      if (m->solvesSteadyState() && !m->steadyStateReached())
        r.steadyStateMissed += (r.steadyStateMissed.empty() ? "" : "; ") + m->steadyStateGap();
  if ((r.interruptedBy != 0 || checkpoint_.final) && lastCheckpointStep != ts.step) checkpoint();
  if (fieldOutput_.final && lastFrameStep != ts.step && r.interruptedBy == 0) writeFrame();
  progress.finish();
  r.steps = ts.step;
  r.simTime = ts.time;
  {
    ScopedTimer t(timers_, "metrics");
    meshMetrics(r.metrics);
    if (r.steadyStateReached) r.metrics["time.steady_state_reached"] = 1.0;
    r.metrics["output.field_frames"] = fields.frames();
    for (const Module* m : reporting_) m->addMetrics(r.metrics);
  }
  return r;
}

namespace {

constexpr const char* kCheckpointPrefix = "checkpoint_";

/// The step of a checkpoint file name, or -1 for another file.
long long checkpointStep(const fs::path& file) {
  const std::string n = file.filename().string();
  const std::size_t p = std::strlen(kCheckpointPrefix);
  if (n.size() <= p + 3 || n.compare(0, p, kCheckpointPrefix) != 0 || file.extension() != ".h5") return -1;
  const std::string digits = n.substr(p, n.size() - p - 3);
  if (digits.empty() || digits.size() > 15 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoll(digits);
}

/// The checkpoint files of a folder by step.
std::map<long long, fs::path> checkpointFiles(const fs::path& dir) {
  std::map<long long, fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const long long step = checkpointStep(e.path());
    if (step >= 0) files[step] = e.path();
  }
  return files;
}

/// Scene keys a restart may change: when it ends and what it writes, not what it computes.
bool restartMayChange(const std::string& difference) {
  for (const char* key : {"time.endTime:", "time.maxSteps:", "time.stopAtSteadyState:", "name:", "description:"})
    if (difference.rfind(key, 0) == 0) return true;
  return difference.rfind("output.", 0) == 0;
}

}  // namespace

namespace {
/// Rank r's part of the checkpoint `main` (rank 0's file): `checkpoint_<step>.rank<r>.h5`.
std::string rankFile(const std::string& main, int rank) {
  const fs::path p(main);
  return (p.parent_path() / (p.stem().string() + ".rank" + std::to_string(rank) + ".h5")).string();
}
}  // namespace

std::string Simulation::writeCheckpoint(const std::string& outDir, const TimeState& ts, const io::FieldSeries& fields,
                                        double nextFrameTime, long long lastFrameStep, double wall) {
  const fs::path dir = fs::path(outDir) / "checkpoints";
  char name[64];
  std::snprintf(name, sizeof name, "%s%09lld.h5", kCheckpointPrefix, static_cast<long long>(ts.step));
  const std::string path = (dir / name).string();
  // Every rank writes its file (its part's points and state, no gather); rank 0 commits its own
  // only when all others have committed theirs.
  std::string failure;
  std::optional<io::Hdf5File> file;
  try {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec && !fs::is_directory(dir)) throw OutputError("cannot create '" + dir.string() + "': " + ec.message());
    file.emplace(io::Hdf5File::create(rank_ == 0 ? path : rankFile(path, rank_)));
    io::StateWriter run(*file, "/run");
    run.putInt("ranks", ranks_);
    run.putInt("rank", rank_);
    if (rank_ == 0) {
      run.putText("version", MFSI_VERSION);
      run.putText("scene", sceneText_);
      run.putInt("step", ts.step);
      run.put("time", std::vector<double>{ts.time, ts.dt, ts.dtOld, nextFrameTime, wall});
      run.putInt("lastFrameStep", lastFrameStep);
      run.putInt("firstStep", firstStep_);
      run.putText("fields", fields.state());
      run.putInt("partition", partitionHash_);
    }
    if (hasMesh_) {  // the moved points of the mesh this rank computes on, by node (carried by global id)
      io::StateWriter mesh(*file, "/mesh");
      mesh.putView("points", ownMesh().points(), io::Entity::Nodes);
    }
    if (ranks_ > 1 && hasMesh_) {  // what carries the state to another decomposition (restore)
      if (!partIds_) partIds_ = io::partIds(localMesh_, partFaces_, counts_);
      io::StateWriter part(*file, "/run/part");
      io::writePartIds(part, *partIds_);
    }
    for (const Module* m : reporting_) {
      io::StateWriter w(*file, "/modules/" + m->name());
      m->saveState(w);
    }
    if (rank_ != 0) file->commit();
  } catch (const OutputError& e) {
    failure = e.what();
  }
  if (ranks_ > 1) {
    int ok = failure.empty() ? 1 : 0, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all && failure.empty()) {
      failure = "another rank could not write its part of checkpoint '" + path + "'";
      std::error_code ec;
      if (rank_ > 0) fs::remove(rankFile(path, rank_), ec);  // no orphaned part
    }
  }
  if (!failure.empty()) throw OutputError(failure);  // rank 0's file, uncommitted, is removed
  if (rank_ == 0) file->commit();
  file.reset();
  // The most recent `keep` stay; rank 0 names the steps to drop, every rank drops its files.
  std::vector<long long> drop;
  if (rank_ == 0) {
    const auto files = checkpointFiles(dir);
    long long excess = static_cast<long long>(files.size()) - checkpoint_.keep;
    for (const auto& [step, f] : files) {
      if (excess-- <= 0) break;
      drop.push_back(step);
    }
  }
  if (ranks_ > 1) {
    long long n = static_cast<long long>(drop.size());
    MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    drop.resize(static_cast<std::size_t>(n));
    MPI_Bcast(drop.data(), static_cast<int>(n), MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  }
  for (long long step : drop) {
    std::snprintf(name, sizeof name, "%s%09lld.h5", kCheckpointPrefix, step);
    const std::string old = (dir / name).string();
    std::error_code ec;
    if (ranks_ > 1 && rank_ > 0) fs::remove(rankFile(old, rank_), ec);
    if (rank_ == 0) {
      fs::remove(old, ec);
      // Parts of the same step from a run on more ranks than this one.
      for (int r = 1; fs::exists(rankFile(old, r), ec); ++r) fs::remove(rankFile(old, r), ec);
    }
  }
  return path;
}

std::string Simulation::findCheckpoint(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return path;
  if (!fs::is_directory(path, ec))
    throw InputError("--restart '" + path + "': no such run folder or checkpoint file");
  const auto files = checkpointFiles(fs::path(path) / "checkpoints");
  if (files.empty())
    throw InputError("--restart '" + path + "': no checkpoint in '" + (fs::path(path) / "checkpoints").string() +
                     "' (a run writes them as output.checkpoint asks, and when SIGINT or SIGTERM stops it)");
  return files.rbegin()->second.string();
}

std::string Simulation::runFolderOf(const std::string& checkpointFile) {
  const fs::path dir = fs::absolute(checkpointFile).parent_path();
  return (dir.filename() == "checkpoints" ? dir.parent_path() : dir).string();
}

io::Hdf5File Simulation::carryCheckpoint(const io::Hdf5File& first, const std::string& checkpointFile,
                                         int writtenOn) {
  if (!hasMesh_ && writtenOn != ranks_)
    throw InputError("--restart: '" + checkpointFile + "' was written by a run on " + std::to_string(writtenOn) +
                     " rank(s); a scene without a mesh continues on as many (mpirun -np " +
                     std::to_string(writtenOn) + "), not " + std::to_string(ranks_));
  std::vector<io::Hdf5File> others;
  for (int r = 1; r < writtenOn; ++r) {
    const std::string part = rankFile(checkpointFile, r);
    try {
      others.push_back(io::Hdf5File::openRead(part));
    } catch (const OutputError& e) {
      throw InputError("--restart: '" + checkpointFile + "' was written by " + std::to_string(writtenOn) +
                       " ranks, and rank " + std::to_string(r) + "'s part cannot be read: " + e.what());
    }
  }
  std::vector<const io::Hdf5File*> parts{&first};
  for (const io::Hdf5File& f : others) parts.push_back(&f);
  std::vector<io::PartIds> old;
  for (const io::Hdf5File* f : parts) {
    if (writtenOn > 1 && !f->has("/run/part/cells"))
      throw InputError("--restart: '" + f->path() + "' has no global ids (/run/part): it was written before "
                       "checkpoints could move to another decomposition; continue it on " +
                       std::to_string(writtenOn) + " ranks with the same partition");
    old.push_back(writtenOn > 1 ? io::readPartIds(io::StateReader(*f, "/run/part"), counts_)
                                : io::wholeMeshIds(counts_));
  }
  const io::PartIds mine = ranks_ > 1 ? io::partIds(localMesh_, partFaces_, counts_) : io::wholeMeshIds(counts_);
  io::Hdf5File carried = io::Hdf5File::scratch(checkpointFile + " (carried to rank " + std::to_string(rank_) +
                                               " of " + std::to_string(ranks_) + ")");
  io::redistribute(parts, old, mine, carried);
  return carried;
}

void Simulation::restorePoints(const io::Hdf5File& first, const io::Hdf5File& states) {
  if (first.has(io::entityTagPath("/mesh/points"))) {  // each rank's file has its part's points
    io::StateReader(states, "/mesh").getView("points", ownMesh().points());
    return;
  }
  // A checkpoint written before its parts held their points: rank 0's file has the whole mesh's
  // (every rank reads them and keeps its own).
  if (ranks_ == 1) {
    io::StateReader(first, "/mesh").getView("points", mesh_.points());
    return;
  }
  Real3View all("mfsi::run::checkpointPoints", static_cast<std::size_t>(counts_.nodes));
  io::StateReader(first, "/mesh").getView("points", all);
  auto whole = Kokkos::create_mirror_view_and_copy(HostSpace(), all);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), localMesh_.nodeGlobalIds());
  auto x = Kokkos::create_mirror_view(localMesh_.points());
  for (lid_t i = 0; i < localMesh_.nNodes(); ++i)
    for (int c = 0; c < 3; ++c) x(i, c) = whole(gid(i), c);
  Kokkos::deep_copy(localMesh_.points(), x);
}

std::vector<std::string> Simulation::restore(const std::string& checkpointFile, bool allowChanges) {
  ScopedTimer timer(timers_, "restore");
  io::Hdf5File file = [&] {
    try {
      return io::Hdf5File::openRead(checkpointFile);
    } catch (const OutputError& e) {
      throw InputError(std::string("--restart: ") + e.what());
    }
  }();
  const io::StateReader run(file, "/run");
  const long long writtenOn = run.has("ranks") ? run.integer("ranks") : 1;
  if (writtenOn < 1 || writtenOn > 1000000)
    throw InputError("--restart: '" + checkpointFile + "': /run/ranks is " + std::to_string(writtenOn));
  // Another rank count or partition: the state is carried across by global ids (below).
  const bool carried = writtenOn != ranks_ || (ranks_ > 1 && run.integer("partition") != partitionHash_);
  const std::string before = run.text("scene");
  std::string refused;
  std::vector<std::string> accepted;
  for (const std::string& d : sceneDifferences(before, sceneText_)) {
    if (restartMayChange(d)) continue;
    if (allowChanges && d.rfind("mesh.", 0) != 0 && d.rfind("time.dt:", 0) != 0)
      accepted.push_back(d);
    else
      refused += "\n  " + d;
  }
  if (!refused.empty())
    throw InputError("--restart: the scene differs from the one that wrote '" + checkpointFile +
                     "' in what the run computes (only time.endTime, time.maxSteps and output may change; with "
                     "--allow-changes anything but the mesh and time.dt):" + refused);
  StartState& st = start_;
  st.time.step = static_cast<int>(run.integer("step"));
  const auto tv = run.doubles("time", 5);
  st.time.time = tv[0];
  st.time.dt = tv[1];
  st.time.dtOld = tv[2];
  st.nextFrameTime = tv[3];
  st.wallSeconds = tv[4];
  st.lastFrameStep = run.integer("lastFrameStep");
  st.firstStep = run.integer("firstStep");
  st.fields = run.text("fields");
  if (st.time.step > nSteps_)
    throw InputError("--restart: the checkpoint is at step " + std::to_string(st.time.step) + " (t = " +
                     formatReal(st.time.time) + "), beyond the scene's end (" + std::to_string(nSteps_) +
                     " steps): raise time.endTime to continue");
  // Several ranks: each rank's modules from its own file; another decomposition: from a file in
  // memory that this rank's part of the state is carried into from every part of the old one.
  std::optional<io::Hdf5File> own;
  if (carried) {
    own.emplace(carryCheckpoint(file, checkpointFile, static_cast<int>(writtenOn)));
    carriedFromRanks_ = static_cast<int>(writtenOn);
  } else if (rank_ > 0) {
    const std::string part = rankFile(checkpointFile, rank_);
    try {
      own.emplace(io::Hdf5File::openRead(part));
    } catch (const OutputError& e) {
      throw InputError(std::string("--restart: rank ") + std::to_string(rank_) + "'s part: " + e.what());
    }
  }
  const io::Hdf5File& states = own ? *own : file;
  if (hasMesh_) restorePoints(file, states);
  // Parts first, then the module that owns them (the coupling places its mounted membranes by
  // the bodies' state).
  for (auto& m : modules_) {
    for (Module* p : m->parts()) p->loadState(io::StateReader(states, "/modules/" + p->name()));
    m->loadState(io::StateReader(states, "/modules/" + m->name()));
  }
  st.restored = true;
  completedSteps_ = st.time.step;
  completedTime_ = st.time.time;
  return accepted;
}

}  // namespace mfsi
