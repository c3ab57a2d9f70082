#pragma once
/// \file
/// \brief Running the project's Python scripts (scripts/*.py) from the `mfsi` command: finding a
/// script, finding an interpreter that can import what it needs, and running a program without a
/// shell. Shared by `mfsi plot` and `mfsi study`.
#include <filesystem>
#include <string>
#include <vector>

namespace mfsi {

/// runProgram's result when the program could not be started (not found, not executable).
constexpr int kCannotStart = -1;

/// \brief Runs args[0] (a path, or a name looked up on PATH) with `args` as its argv (posix_spawn,
/// never a shell: any argument is safe), waits for it and returns its exit code: kCannotStart if it
/// could not be started, 128 + N if signal N ended it. `quiet` sends its output to /dev/null.
///
/// While it waits, SIGINT and SIGTERM do not end this process: the child decides how to stop. A
/// signal from the terminal reaches the child by itself (it is in the same process group); one sent
/// to this process alone (`kill`) is passed on to the child.
int runProgram(const std::vector<std::string>& args, bool quiet);

/// \brief The script `name` (e.g. "plot_run.py"): the one installed with this executable
/// (<prefix>/share/mfsi/scripts), else the source tree's scripts/. Empty if neither exists.
std::filesystem::path findScript(const std::string& name);

/// \brief The first interpreter that has matplotlib (and so numpy) of: $MFSI_PLOT_PYTHON when set
/// (then the only one tried), the one CMake found at configure time, /usr/bin/python3, python3 on
/// PATH. The package is looked up (importlib.util.find_spec), not imported: that takes a second.
/// Empty if none has it, with `tried` listing each candidate and why it was passed over.
std::string findPlotPython(std::string& tried);

/// \brief The message for no interpreter found by findPlotPython: what was tried and how to install
/// matplotlib or name an interpreter.
std::string noPlotPythonMessage(const std::string& tried);

/// \brief The script `name` and an interpreter that has matplotlib, or the command's exit code
/// when either is missing (1: no script, an installation fault; 2: no interpreter, with how to get
/// one), the message printed. 0 when both were found.
int findScriptAndPython(const std::string& name, std::filesystem::path& script, std::string& python);

}  // namespace mfsi
