// mfsi — the membrane-fsi command.
//
//   mfsi run                                  # the default scene (membrane-channel), results in results/<scene>/
//   mfsi run cases/box.yaml --out /tmp/box --threads 2 [--overwrite]
//   mfsi run --restart /tmp/box               # continue a run from its latest checkpoint
//   mfsi run box --set mesh.blocks.0.cells=[32,16,16] --set mesh.blocks.1.cells=[48,16,16]
//   mpirun -np 4 mfsi run flexible-cavity     # decomposed over 4 ranks (METIS at start-up)
//   mfsi partition flexible-cavity -n 4       # the decomposition, written to results/flexible-cavity-partition4.txt
//   mpirun -np 4 mfsi run flexible-cavity --partition results/flexible-cavity-partition4.txt
//   mfsi check cases/box.yaml                 # validate without running (also builds the mesh)
//   mfsi check --describe                     # every scene key with type, default, units, doc
//   mfsi scenes                               # built-in scenes
//   mfsi plot /tmp/box [--out DIR]            # PNGs of a run's time series (and a 2D field) in /tmp/box/plots/
//   mfsi study cavity --vary mesh.refine=0.5,1,2 --metric fluid.ghia_u_max_err --reference 0   # error vs cost
//   mfsi --version
//
// Exit codes: 0 ok, 2 bad input (scene, mesh, command line), 3 diverged, 4 results could not be
// saved (a failed write, a full disk: summary.json says status "error", or there is none when it
// could not be written itself), 1 internal error, 130 / 143 stopped by SIGINT / SIGTERM (after a
// checkpoint: continue with --restart).
// Every `run` writes <out>/summary.json (also on errors), <out>/scene.yaml and <out>/steps.csv (and
// fields.xdmf with fields/ as the scene's `output` asks); a folder that holds an earlier run's
// results is refused (exit 2, nothing written) unless --overwrite.
#include "Partition.hpp"
#include "Plot.hpp"
#include "SceneFiles.hpp"
#include "Study.hpp"
#include "coupling/Simulation.hpp"
#include "core/Interrupt.hpp"
#include "core/RunLog.hpp"
#include "core/parallel/FailureAgreement.hpp"

#include <CLI/CLI.hpp>
#include <mpi.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace fs = std::filesystem;

namespace {

constexpr const char* kDefaultScene = "membrane-channel";
/// How long a rank that failed waits for the others to join the outcome agreement before it
/// concludes they are stuck in a collective and aborts the job.
constexpr double kOutcomeTimeoutSeconds = 10.0;

std::vector<fs::path> caseDirs() {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("MFSI_CASES_DIR")) dirs.emplace_back(env);
  dirs.emplace_back(MFSI_SOURCE_CASES_DIR);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / "share" / "mfsi" / "cases");
  return dirs;
}

}  // namespace

/// A path to a scene file, or the name of a built-in scene.
fs::path resolveScene(const std::string& arg) {
  if (fs::exists(arg) && !fs::is_directory(arg)) return arg;
  for (const auto& d : caseDirs()) {
    const fs::path p = d / (arg + ".yaml");
    if (fs::exists(p)) return p;
  }
  throw mfsi::InputError("cannot open scene file '" + arg + "' (not a file, nor a built-in scene; see `mfsi scenes`)");
}

std::string sceneName(const mfsi::SceneConfig& cfg, const fs::path& file) {
  const std::string n = cfg.get<std::string>("name");
  return n.empty() ? file.stem().string() : n;
}

namespace {

int threadCount() { return mfsi::ExecSpace().concurrency(); }

/// True when a parallel launcher started this process: Open MPI's mpirun, a PMI or PMIx launcher
/// (MPICH's hydra, Slurm's srun), MVAPICH; MFSI_MPI=1 forces MPI on, MFSI_MPI=0 off.
bool launchedByMpi() {
  if (const char* force = std::getenv("MFSI_MPI")) return std::string(force) != "0";
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK", "PMIX_RANK", "MV2_COMM_WORLD_SIZE"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

int commandScenes() {
  for (const auto& d : caseDirs()) {
    if (!fs::is_directory(d)) continue;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(d))
      if (e.path().extension() == ".yaml") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    std::cout << "scenes in " << d.string() << ":\n";
    for (const auto& f : files) {
      std::string description;
      try {
        description = mfsi::SceneConfig::load(f.string(), mfsi::sceneSchema()).get<std::string>("description");
      } catch (const std::exception& e) {
        description = std::string("(invalid: ") + e.what() + ")";
      }
      std::cout << "  " << f.stem().string() << (f.stem() == kDefaultScene ? " (default)" : "") << "  — "
                << description << "\n";
    }
    return 0;
  }
  std::cerr << "no scene folder found\n";
  return 2;
}

int commandCheck(const std::string& scene, const std::vector<std::string>& sets, bool describe) {
  if (describe) {
    std::cout << mfsi::describeSchema(mfsi::sceneSchema());
    return 0;
  }
  try {
    const fs::path file = resolveScene(scene);
    const auto cfg = mfsi::SceneConfig::load(file.string(), mfsi::sceneSchema(), sets);
    mfsi::Simulation sim(cfg);
    std::cout << "ok: " << file.string() << ": scene '" << sceneName(cfg, file) << "', "
              << (sim.hasMesh() ? sim.meshCounts().cells : 0) << " cells, "
              << (sim.hasMesh() ? sim.meshCounts().nodes : 0)
              << " nodes, " << sim.modules().size() << " module(s)\n";
    return 0;
  } catch (const mfsi::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

/// What a run writes into its output folder (files, and the folder of field frames).
const char* const kRunOutputs[] = {"summary.json", "scene.yaml", "steps.csv",  "bodies.csv",
                                   "fields.xdmf",  "fields",     "checkpoints", "plots"};

/// Make `out` ready for a run before anything is built: a folder that holds another run's results
/// is refused unless `overwrite` (which removes exactly those results, nothing else of the
/// folder's), so a run never mixes its files with an earlier run's nor replaces its summary.
/// Throws InputError (exit 2) with nothing written.
void prepareOutput(const std::string& out, bool overwrite) {
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    throw mfsi::InputError("--out '" + out + "' is a file, not a folder");
  std::vector<std::string> found;
  for (const char* name : kRunOutputs)
    if (fs::exists(fs::path(out) / name, ec)) found.push_back(name);
  if (!found.empty() && !overwrite) {
    std::string list;
    for (const auto& f : found) list += (list.empty() ? "" : ", ") + f;
    throw mfsi::InputError("--out '" + out + "' holds the results of an earlier run (" + list +
                           "): give another --out, or --overwrite to replace them");
  }
  for (const auto& f : found) {
    fs::remove_all(fs::path(out) / f, ec);
    if (ec) throw mfsi::InputError("--overwrite: cannot remove '" + (fs::path(out) / f).string() + "': " + ec.message());
  }
  fs::create_directories(out, ec);
  if (ec) throw mfsi::InputError("--out '" + out + "': cannot create the folder: " + ec.message());
  const fs::path probe = fs::path(out) / ".mfsi-write-test";
  {
    std::ofstream test(probe);
    test << "ok";
    test.flush();
    if (!test) throw mfsi::InputError("--out '" + out + "': the folder is not writable");
  }
  fs::remove(probe, ec);
}

/// Same folder (both exist and are one)?
bool sameFolder(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

int commandRun(std::string sceneArg, const std::vector<std::string>& sets, std::string out, bool overwrite,
               const std::string& restart, bool allowChanges, const std::string& partitionMap) {
  const double t0 = mfsi::wallSeconds();
  mfsi::installInterruptHandlers();
  // --restart: the checkpoint, the folder of the run that wrote it (the default --out: the run
  // continues its files there) and its scene (the default scene).
  std::string checkpoint;
  bool continueFiles = false;
  if (!restart.empty()) {
    try {
      checkpoint = mfsi::Simulation::findCheckpoint(restart);
    } catch (const mfsi::InputError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    const std::string runFolder = mfsi::Simulation::runFolderOf(checkpoint);
    if (out.empty()) out = runFolder;
    if (sceneArg.empty()) sceneArg = (fs::path(runFolder) / "scene.yaml").string();
    continueFiles = sameFolder(out, runFolder);
  }
  if (sceneArg.empty()) sceneArg = kDefaultScene;
  mfsi::RunSummary summary;
  summary.scene = sceneArg;
  summary.backend = mfsi::backendName();
  summary.threads = threadCount();
  int rank = 0, mpiUp = 0;
  summary.ranks = 1;
  MPI_Initialized(&mpiUp);
  if (mpiUp) {
    MPI_Comm_size(MPI_COMM_WORLD, &summary.ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  }
  int code = 0;
  bool started = false;  ///< the run has begun writing into `out`
  std::unique_ptr<mfsi::Simulation> sim;
  if (out.empty()) out = (fs::path("results") / fs::path(sceneArg).stem()).string();
  int prepared = 1;
  try {
    if (rank == 0 && !continueFiles) prepareOutput(out, overwrite);
  } catch (const mfsi::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";  // no summary: the folder is not ours to write
    prepared = 0;
  }
  if (summary.ranks > 1) MPI_Bcast(&prepared, 1, MPI_INT, 0, MPI_COMM_WORLD);  // every rank stops, or none
  if (!prepared) return 2;
  // On several ranks the solvers agree on every global decision (residuals, divergence, input
  // checks), so those errors arise on every rank at once. At the end every rank joins an
  // agreement on the outcome (core/parallel/FailureAgreement): rank 0 then prints the one message
  // (the lowest failed rank's) and writes the one summary. A rank that failed alone while the
  // others wait in a collective it left times out there: it prints, writes the summary itself
  // and MPI_Abort stops them all.
  MPI_Comm outcomeComm = MPI_COMM_NULL;
  if (summary.ranks > 1) MPI_Comm_dup(MPI_COMM_WORLD, &outcomeComm);
  std::string reportLine;
  auto report = [&](const std::string& line) {
    reportLine = line;
    if (summary.ranks == 1) std::cerr << line << "\n";
  };
  try {
    const fs::path file = resolveScene(sceneArg);
    const auto cfg = mfsi::SceneConfig::load(file.string(), mfsi::sceneSchema(), sets);
    summary.scene = sceneName(cfg, file);
    const std::string resolved = cfg.resolvedYaml();
    if (rank == 0) {
      std::cout << "mfsi " << MFSI_VERSION << " | scene " << file.string() << " | backend " << summary.backend << " x"
                << summary.threads << " threads | " << summary.ranks << " rank(s)\n"
                << "---- resolved scene ----\n"
                << resolved << "------------------------\n";
    }
    sim = std::make_unique<mfsi::Simulation>(cfg, partitionMap);
    if (sim->hasMesh()) {
      summary.cells = sim->meshCounts().cells;
      summary.nodes = sim->meshCounts().nodes;
    }
    if (!checkpoint.empty()) {
      const std::vector<std::string> changes = sim->restore(checkpoint, allowChanges);
      if (rank == 0) {
        std::cout << "continuing from " << checkpoint << " (step " << sim->completedSteps() << ", t = "
                  << sim->completedTime() << ")\n";
        for (const std::string& c : changes) std::cout << "  changed on restart: " << c << "\n";
        if (sim->carriedFromRanks() > 0)
          std::cout << "  written on " << sim->carriedFromRanks() << " rank(s), continued on " << sim->ranks()
                    << ": the state is carried by global ids (to the solvers' tolerances, not bitwise)\n";
      }
    }
    started = true;
    if (rank == 0) mfsi::writeTextAtomically(out + "/scene.yaml", resolved);
    const auto result = sim->run(out, rank == 0 && mfsi::stdoutIsTerminal(), continueFiles);
    summary.steps = result.steps;
    summary.simTime = result.simTime;
    summary.metrics = result.metrics;
    if (result.steadyStateReached && rank == 0)
      std::cout << "steady state reached after step " << result.steps
                << ": every residual below its tolerance (fluid.pimple.outerTolerance)\n";
    if (!result.steadyStateMissed.empty()) {
      summary.status = "unconverged";
      summary.error = "steady state not reached in " + std::to_string(result.steps) + " steps: " +
                      result.steadyStateMissed + " (more steps: time.endTime; or time.stopAtSteadyState: false)";
      report("unconverged: " + summary.error);
      code = 5;
    }
    if (result.interruptedBy != 0) {
      summary.status = "interrupted";
      summary.error = std::string("stopped by ") + mfsi::signalName(result.interruptedBy) + " after step " +
                      std::to_string(result.steps) + "; continue with: mfsi run --restart " + out;
      report("interrupted: " + summary.error +
             (result.lastCheckpoint.empty() ? "" : " (checkpoint " + result.lastCheckpoint + ")"));
      code = 128 + result.interruptedBy;
    }
  } catch (const mfsi::InputError& e) {
    summary.status = "error";
    summary.error = e.what();
    report(std::string("error: ") + e.what());
    code = 2;
    // A restart that cannot continue leaves the folder of the run it was to continue untouched.
    if (continueFiles && !started) return code;
  } catch (const mfsi::DivergenceError& e) {
    summary.status = "diverged";
    summary.error = e.what();
    // The last good state, when the run saved one (checkpoints are written after complete steps).
    if (sim && !sim->lastCheckpoint().empty())
      summary.error += "; last good checkpoint: " + sim->lastCheckpoint() + " (mfsi run --restart it --allow-changes --set ... to go on with other settings)";
    report("diverged: " + summary.error);
    code = 3;
  } catch (const mfsi::OutputError& e) {
    summary.status = "error";
    summary.error = std::string("output: ") + e.what();
    report(std::string("error: results not saved: ") + e.what());
    code = 4;
  } catch (const std::exception& e) {
    summary.status = "error";
    summary.error = std::string("internal error") + (summary.ranks > 1 ? " on rank " + std::to_string(rank) : "") +
                    ": " + e.what();
    report(summary.error);
    code = 1;
  }
  if (sim) {
    summary.timers = sim->timers().all();
    summary.steps = sim->completedSteps();  // how far a diverged run got
    summary.simTime = sim->completedTime();
  }
  summary.wallSeconds = mfsi::wallSeconds() - t0;
  bool writer = rank == 0, abortAll = false;
  if (summary.ranks > 1) {
    const mfsi::FailureAgreement agreed =
        mfsi::agreeOnOutcome(outcomeComm, {code, summary.status, summary.error, reportLine}, kOutcomeTimeoutSeconds);
    if (!agreed.complete) {
      // The others are stuck in a collective this rank left: it speaks for the run.
      std::cerr << reportLine << (reportLine.find("rank ") == std::string::npos ? " (rank " + std::to_string(rank) + ")" : "")
                << "\n";
      writer = abortAll = true;
    } else {
      if (agreed.firstFailed >= 0) {
        code = agreed.outcome.code;
        summary.status = agreed.outcome.status;
        summary.error = agreed.outcome.error;
        if (rank == 0) std::cerr << agreed.outcome.message << "\n";
      }
      MPI_Comm_free(&outcomeComm);
    }
  }
  if (writer) {
    try {
      mfsi::writeSummary(out, summary);
      std::cout << (code == 0                           ? "done"
                    : summary.status == "interrupted"   ? "interrupted"
                    : summary.status == "unconverged" ? "not converged"
                                                      : "failed")
                << " in " << summary.wallSeconds << " s; results in " << out
                << "/ (summary.json)\n";
    } catch (const std::exception& e) {
      // No summary rather than a stale one (a continued run's earlier summary): a run without
      // summary.json did not finish. The exit code keeps the run's own failure, else 4.
      std::error_code ec;
      fs::remove(fs::path(out) / "summary.json", ec);
      std::cerr << "error: results not saved: cannot write the summary: " << e.what() << "\n";
      if (code == 0) code = 4;
    }
  }
  if (abortAll) MPI_Abort(MPI_COMM_WORLD, code);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"membrane-fsi: fluid-structure interaction of flexible membranes"};
  app.set_version_flag("--version", std::string("mfsi ") + MFSI_VERSION);
  app.require_subcommand(1);

  std::string scene, out, restart, partitionMap;
  std::vector<std::string> sets;
  int threads = 0;
  bool describe = false;
  bool overwrite = false;
  bool allowChanges = false;

  auto* run = app.add_subcommand("run", "run a scene (default: the built-in default scene)");
  run->add_option("scene", scene, "scene file, or the name of a built-in scene");
  // Each --set takes one value (repeat it for more), so a scene after it stays the scene.
  run->add_option("--set", sets, "override a scene value: --set a.b.c=value (repeatable)")->allow_extra_args(false);
  run->add_option("--out", out, "output folder (default: results/<scene>)");
  run->add_flag("--overwrite", overwrite, "replace the results of an earlier run in the output folder");
  auto* restartOption = run->add_option("--restart", restart,
                  "continue a run from a checkpoint: its folder (the latest checkpoint in it) or a checkpoint "
                  "file; the scene defaults to the run's scene.yaml and --out to its folder (continuing its files)");
  run->add_flag("--allow-changes", allowChanges,
                "with --restart: let the scene differ from the checkpoint's in other settings than time.endTime, "
                "time.maxSteps and output (not the mesh nor time.dt), e.g. to go on from a diverged run's last "
                "good checkpoint with other solver settings")
      ->needs(restartOption);
  run->add_option("--threads", threads, "host threads (default: OMP_NUM_THREADS or all cores)")->check(CLI::PositiveNumber);
  run->add_option("--partition", partitionMap,
                  "on several ranks: the cell -> rank map `mfsi partition` wrote, instead of METIS at start-up");

  auto* check = app.add_subcommand("check", "validate a scene without running it");
  check->add_option("scene", scene, "scene file, or the name of a built-in scene");
  check->add_option("--set", sets, "override a scene value: --set a.b.c=value (repeatable)")->allow_extra_args(false);
  check->add_flag("--describe", describe, "list every scene key with type, default, units and doc");

  app.add_subcommand("scenes", "list the built-in scenes");

  int partitionRanks = 0;
  std::string partitionOut;
  auto* partition = app.add_subcommand(
      "partition", "decompose a scene's mesh over N ranks (METIS, membranes' cells kept together): figures and the map");
  partition->add_option("scene", scene, "scene file, or the name of a built-in scene")->required();
  partition->add_option("-n,--ranks", partitionRanks, "number of ranks")->required()->check(CLI::PositiveNumber);
  partition->add_option("--set", sets, "override a scene value: --set a.b.c=value (repeatable)")->allow_extra_args(false);
  partition->add_option("--out", partitionOut, "file of the cell -> rank map (default: results/<scene>-partition<N>.txt)");

  std::string plotDir, plotOut;
  auto* plot = app.add_subcommand("plot", "PNGs of a run folder's time series (and, for a 2D scene, its last field)");
  plot->add_option("run_dir", plotDir, "a folder written by `mfsi run`")->required();
  plot->add_option("--out", plotOut, "folder for the PNGs (default: RUN_DIR/plots)");

  StudyOptions studyOptions;
  auto* study =
      app.add_subcommand("study",
                         "run a scene over a grid of settings: study.csv, error against wall time (Pareto front) and "
                         "against resolution (observed order); an interrupted study continues where it stopped");
  study->add_option("scene", studyOptions.scene, "scene file, or the name of a built-in scene");
  study
      ->add_option("--vary", studyOptions.vary,
                   "KEY=V1,V2,... values of a scene key (commas inside [..] belong to a value; K1+K2=... sets "
                   "both; VALUE@LEVEL gives a named value a resolution); repeat for the product grid")
      ->allow_extra_args(false);
  study->add_option("--set", studyOptions.sets, "KEY=VALUE for every run (repeatable)")->allow_extra_args(false);
  study->add_option("--metric", studyOptions.metric, "the metric of summary.json to compare");
  study->add_option("--reference", studyOptions.reference,
                    "exact (the metric's <NAME>_exact), exact:METRIC, finest (the finest run; Richardson "
                    "estimate of the limit), richardson (that limit) or a number");
  study->add_option("--jobs", studyOptions.jobs, "runs at once (default 1)")->check(CLI::PositiveNumber);
  study
      ->add_option("--threads", studyOptions.threads,
                   "threads of the whole study, split between the jobs (default: OMP_NUM_THREADS or all cores)")
      ->check(CLI::PositiveNumber);
  study->add_option("--out", studyOptions.out, "study folder (default: results/<scene>-study)");
  study->add_flag("--self-test", studyOptions.selfTest, "check the study's fits on synthetic data, then exit");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a command-line error is bad input: exit 2 like any other.
    return app.exit(e) == 0 ? 0 : 2;
  }

  // A study only starts `mfsi run` processes: no MPI or Kokkos of its own.
  if (app.got_subcommand("study")) {
    if (!studyOptions.selfTest && (studyOptions.scene.empty() || studyOptions.vary.empty() ||
                                   studyOptions.metric.empty() || studyOptions.reference.empty())) {
      std::cerr << "error: mfsi study needs SCENE, --vary KEY=V1,V2,..., --metric NAME and --reference "
                   "exact|exact:METRIC|finest|richardson|VALUE (see mfsi study --help)\n";
      return 2;
    }
    return commandStudy(studyOptions);
  }

  // MPI starts only under a launcher (mpirun, srun): a singleton MPI_Init and MPI_Finalize cost
  // 0.3 s of every run's start-up (Open MPI 4.1), more than a small steady scene's whole solve.
  const bool mpi = launchedByMpi();
  if (mpi) MPI_Init(&argc, &argv);
  int code = 0;
  {
    // Kokkos options are passed as arguments: the spelling of the thread-count flag changed in 4.x.
    std::vector<std::string> kargs = {argv[0], "--kokkos-disable-warnings"};
    if (threads > 0) {
#if KOKKOS_VERSION >= 40000
      kargs.push_back("--kokkos-num-threads=" + std::to_string(threads));
#else
      kargs.push_back("--kokkos-threads=" + std::to_string(threads));
#endif
    }
    std::vector<char*> kargv;
    for (auto& a : kargs) kargv.push_back(a.data());
    int kargc = static_cast<int>(kargv.size());
    Kokkos::ScopeGuard kokkos(kargc, kargv.data());
    int worldRank = 0;
    if (mpi) MPI_Comm_rank(MPI_COMM_WORLD, &worldRank);
    if (app.got_subcommand("partition")) {
      code = worldRank == 0 ? commandPartition(scene, sets, partitionRanks, partitionOut) : 0;
    } else if (app.got_subcommand("run")) {
      code = commandRun(scene, sets, out, overwrite, restart, allowChanges, partitionMap);
    } else if (app.got_subcommand("plot")) {
      code = commandPlot(plotDir, plotOut);
    } else if (app.got_subcommand("check")) {
      code = commandCheck(scene.empty() ? kDefaultScene : scene, sets, describe);
    } else {
      code = commandScenes();
    }
  }
  if (mpi) MPI_Finalize();
  return code;
}
