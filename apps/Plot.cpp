// mfsi plot — pictures of a run folder.
//
//   mfsi plot results/cylinder                  # PNGs in results/cylinder/plots/, their names printed
//   mfsi plot results/cylinder --out /tmp/cyl
//   MFSI_PLOT_PYTHON=~/venv/bin/python mfsi plot results/cylinder
//
// The drawing is Python's (scripts/plot_run.py, matplotlib); this file finds the script and an
// interpreter that can import matplotlib (apps/Python.cpp says which), and runs it without a
// shell: any folder name is safe.
#include "Plot.hpp"

#include "Python.hpp"

#include <filesystem>
#include <iostream>
#include <vector>

namespace fs = std::filesystem;

namespace {

constexpr int kBadInput = 2;

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
  fs::path script;
  std::string python;
  if (const int code = mfsi::findScriptAndPython("plot_run.py", script, python); code != 0) return code;
  std::vector<std::string> args = {python, script.string()};
  if (!outDir.empty()) args.push_back("--out=" + outDir);
  args.push_back("--");  // a folder name starting with '-' is still a folder name
  args.push_back(runDir);
  const int rc = mfsi::runProgram(args, false);
  if (rc == mfsi::kCannotStart) {
    std::cerr << "error: cannot run " << python << " " << script.string() << "\n";
    return 1;
  }
  return rc;
}
