// mfsi plot — pictures of a run folder.
//
//   mfsi plot results/cylinder                  # PNGs in results/cylinder/plots/, their names printed
//   mfsi plot results/cylinder --out /tmp/cyl
//   MFSI_PLOT_PYTHON=~/venv/bin/python mfsi plot results/cylinder
//
// The drawing is Python's (scripts/plot_run.py, matplotlib); this file finds the script and an
// interpreter that can import matplotlib, and runs it. The first python3 on PATH is often a pyenv
// or virtual environment without matplotlib, so the interpreter CMake found with it comes first,
// then Debian's /usr/bin/python3. Arguments reach the interpreter as an argv array (posix_spawn),
// never through a shell: any folder name is safe.
#include "Plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <vector>

extern char** environ;

namespace fs = std::filesystem;

namespace {

constexpr int kBadInput = 2;
constexpr int kCannotStart = -1;

/// Runs args[0] (a path, or a name looked up on PATH) with args, waits for it and returns its exit
/// code; kCannotStart if it could not be started, 1 if a signal ended it. `quiet` sends its
/// output to /dev/null.
int runProgram(const std::vector<std::string>& args, bool quiet) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  }
  std::cout.flush();
  std::cerr.flush();
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return kCannotStart;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return kCannotStart;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 127 ? kCannotStart : WEXITSTATUS(status);
  std::cerr << "error: " << args[0] << " ended by signal " << WTERMSIG(status) << "\n";
  return 1;
}

/// plot_run.py: the one installed with this executable (<prefix>/share/mfsi/scripts), else the
/// source tree's. Empty if neither exists.
fs::path findScript() {
  std::vector<fs::path> dirs;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / "share" / "mfsi" / "scripts");
  dirs.emplace_back(MFSI_SOURCE_SCRIPTS_DIR);
  for (const auto& d : dirs)
    if (fs::is_regular_file(d / "plot_run.py", ec)) return d / "plot_run.py";
  return {};
}

/// The first interpreter that imports matplotlib; empty if none does, with `tried` saying why.
std::string findPython(std::string& tried) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("MFSI_PLOT_PYTHON"); env && *env) {
    candidates.emplace_back(env);  // the user's choice: the only one tried
  } else {
    if (*MFSI_PLOT_PYTHON) candidates.emplace_back(MFSI_PLOT_PYTHON);
    candidates.emplace_back("/usr/bin/python3");
    candidates.emplace_back("python3");
  }
  for (const auto& py : candidates) {
    const int rc = runProgram({py, "-c", "import matplotlib"}, true);
    if (rc == 0) return py;
    tried += (tried.empty() ? "" : ", ") + py + (rc == kCannotStart ? " (cannot run)" : " (no matplotlib)");
  }
  return {};
}

}  // namespace

int commandPlot(const std::string& runDir, const std::string& outDir) {
  std::error_code ec;
  if (!fs::is_directory(runDir, ec)) {
    std::cerr << "error: '" << runDir << "' is not a folder\n";
    return kBadInput;
  }
  if (!fs::is_regular_file(fs::path(runDir) / "steps.csv", ec)) {
    std::cerr << "error: '" << runDir
              << "' is not a run folder: it has no steps.csv (`mfsi run --out DIR` writes one)\n";
    return kBadInput;
  }
  const fs::path script = findScript();
  if (script.empty()) {
    std::cerr << "error: plot_run.py not found (in share/mfsi/scripts next to this executable, nor in "
              << MFSI_SOURCE_SCRIPTS_DIR << ")\n";
    return 1;
  }
  std::string tried;
  const std::string python = findPython(tried);
  if (python.empty()) {
    std::cerr << "error: no Python interpreter with matplotlib (tried " << tried
              << "): install it with `apt-get install python3-matplotlib` (or `<python> -m pip install "
                 "matplotlib numpy h5py`), or name an interpreter that has it in MFSI_PLOT_PYTHON\n";
    return kBadInput;
  }
  std::vector<std::string> args = {python, script.string()};
  if (!outDir.empty()) args.push_back("--out=" + outDir);
  args.push_back("--");  // a folder name starting with '-' is still a folder name
  args.push_back(runDir);
  const int rc = runProgram(args, false);
  if (rc == kCannotStart) {
    std::cerr << "error: cannot run " << python << " " << script.string() << "\n";
    return 1;
  }
  return rc;
}
