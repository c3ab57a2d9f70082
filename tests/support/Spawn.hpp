#pragma once
// Start a program (the mfsi command) as a child process, for tests of whole runs: in the background
// with its output to a log file (a test that signals it), or to the end with its output captured;
// optionally with a file-size limit that makes writes fail as on a full disk.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <string>
#include <vector>

extern char** environ;

namespace mfsi::test {

struct SpawnOptions {
  /// RLIMIT_FSIZE of the child in bytes (< 0: inherited), with SIGXFSZ ignored (an ignored signal
  /// stays ignored across exec): a write beyond it fails with EFBIG, as a write to a full disk
  /// fails with ENOSPC, without a file system to fill. It limits every regular file the child
  /// writes, each on its own (pipes and terminals are not limited).
  long long fileSizeLimit = -1;
};

namespace detail {

/// fork + exec with `out` as the child's stdout and stderr. Between fork and exec the child (of a
/// multi-threaded test process) calls only async-signal-safe functions.
inline pid_t forkExec(const std::vector<std::string>& argv, int out, const SpawnOptions& options) {
  std::vector<std::string> args = argv;
  std::vector<char*> cargv;
  for (auto& a : args) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  struct rlimit limit {};
  if (options.fileSizeLimit >= 0) {
    getrlimit(RLIMIT_FSIZE, &limit);
    limit.rlim_cur = static_cast<rlim_t>(options.fileSizeLimit);
  }
  const pid_t pid = fork();
  if (pid != 0) return pid;
  if (out >= 0 && (dup2(out, 1) < 0 || dup2(out, 2) < 0)) _exit(126);
  if (options.fileSizeLimit >= 0) {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    if (sigaction(SIGXFSZ, &ignore, nullptr) != 0 || setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(126);
  }
  execve(cargv[0], cargv.data(), environ);
  _exit(127);
}

}  // namespace detail

/// Start `argv` (argv[0]: the executable's path) in the background, its stdout and stderr to the
/// file `log`. The pid, or -1 when it cannot start.
inline pid_t start(const std::vector<std::string>& argv, const std::string& log, const SpawnOptions& options = {}) {
  const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return -1;
  const pid_t pid = detail::forkExec(argv, fd, options);
  close(fd);
  return pid;
}

/// Wait for a started child: its exit code, or 1000 + the signal that ended it.
inline int finish(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

struct Finished {
  int code = -1;       ///< as finish() gives it
  std::string output;  ///< stdout and stderr
};

/// Run `argv` to the end, its stdout and stderr captured through a pipe (which a file-size limit
/// does not cut short).
inline Finished run(const std::vector<std::string>& argv, const SpawnOptions& options = {}) {
  Finished r;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return r;
  const pid_t pid = detail::forkExec(argv, fds[1], options);
  close(fds[1]);
  if (pid < 0) {
    close(fds[0]);
    return r;
  }
  char buf[4096];
  for (;;) {
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    r.output.append(buf, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  r.code = finish(pid);
  return r;
}

}  // namespace mfsi::test
