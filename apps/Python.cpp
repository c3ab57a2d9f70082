// Running the project's Python scripts. The first python3 on PATH is often a pyenv or virtual
// environment without matplotlib, so the interpreter CMake found with it comes first, then Debian's
// /usr/bin/python3. Arguments reach the interpreter as an argv array (posix_spawn), never through a
// shell.
#include "Python.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <iostream>

extern char** environ;

namespace fs = std::filesystem;

namespace mfsi {

namespace {

volatile sig_atomic_t childPid = 0;

/// SIGINT / SIGTERM while a child runs: passed on when sent to this process alone (si_code <= 0:
/// kill, sigqueue, tgkill). One from the terminal (si_code SI_KERNEL) already reached the whole
/// foreground process group, the child included; sending it again would be a second signal, which
/// makes `mfsi run` stop at once instead of after its step.
extern "C" void forwardToChild(int signal, siginfo_t* info, void*) {
  const pid_t pid = childPid;
  if (pid > 0 && info != nullptr && info->si_code <= 0) kill(pid, signal);
}

/// The handlers of SIGINT and SIGTERM replaced for as long as it lives.
class ForwardSignals {
 public:
  ForwardSignals() {
    struct sigaction sa {};
    sa.sa_sigaction = forwardToChild;
    sa.sa_flags = SA_SIGINFO | SA_RESTART;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_[0]);
    sigaction(SIGTERM, &sa, &old_[1]);
  }
  ~ForwardSignals() {
    childPid = 0;
    sigaction(SIGINT, &old_[0], nullptr);
    sigaction(SIGTERM, &old_[1], nullptr);
  }
  ForwardSignals(const ForwardSignals&) = delete;
  ForwardSignals& operator=(const ForwardSignals&) = delete;

 private:
  struct sigaction old_[2];
};

}  // namespace

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
  // The child starts with the default actions of SIGINT and SIGTERM, even if ours ignore them (a
  // Python whose SIGINT is ignored never raises KeyboardInterrupt).
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
  std::cout.flush();
  std::cerr.flush();
  ForwardSignals forward;
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, argv[0], &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (err != 0) return kCannotStart;
  childPid = pid;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return kCannotStart;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 127 ? kCannotStart : WEXITSTATUS(status);
  std::cerr << "error: " << args[0] << " ended by signal " << WTERMSIG(status) << "\n";
  return 128 + WTERMSIG(status);
}

fs::path findScript(const std::string& name) {
  std::vector<fs::path> dirs;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / "share" / "mfsi" / "scripts");
  dirs.emplace_back(MFSI_SOURCE_SCRIPTS_DIR);
  for (const auto& d : dirs)
    if (fs::is_regular_file(d / name, ec)) return d / name;
  return {};
}

std::string findPlotPython(std::string& tried) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("MFSI_PLOT_PYTHON"); env && *env) {
    candidates.emplace_back(env);  // the user's choice: the only one tried
  } else {
    if (*MFSI_PLOT_PYTHON) candidates.emplace_back(MFSI_PLOT_PYTHON);
    candidates.emplace_back("/usr/bin/python3");
    candidates.emplace_back("python3");
  }
  for (const auto& py : candidates) {
    // Found, not imported: an import of matplotlib takes a second, every time.
    const int rc = runProgram(
        {py, "-c", "import importlib.util, sys; sys.exit(importlib.util.find_spec('matplotlib') is None)"}, true);
    if (rc == 0) return py;
    tried += (tried.empty() ? "" : ", ") + py + (rc == kCannotStart ? " (cannot run)" : " (no matplotlib)");
  }
  return {};
}

std::string noPlotPythonMessage(const std::string& tried) {
  return "no Python interpreter with matplotlib (tried " + tried +
         "): install it with `apt-get install python3-matplotlib` (or `<python> -m pip install matplotlib numpy "
         "h5py`), or name an interpreter that has it in MFSI_PLOT_PYTHON";
}

int findScriptAndPython(const std::string& name, std::filesystem::path& script, std::string& python) {
  script = findScript(name);
  if (script.empty()) {
    std::cerr << "error: " << name << " not found (in share/mfsi/scripts next to this executable, nor in "
              << MFSI_SOURCE_SCRIPTS_DIR << ")\n";
    return 1;
  }
  std::string tried;
  python = findPlotPython(tried);
  if (python.empty()) {
    std::cerr << "error: " << noPlotPythonMessage(tried) << "\n";
    return 2;
  }
  return 0;
}

}  // namespace mfsi
