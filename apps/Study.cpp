// mfsi study — what accuracy costs in time.
//
//   mfsi study membrane-square --vary membranes.0.mesh.rectangle.cells=[8,8],[16,16],[32,32]
//        --metric membrane.period --reference exact --jobs 2 --out /tmp/square
//   mfsi study hencky --vary membranes.0.mesh.disc.core+membranes.0.mesh.disc.rings=4,8,16
//        --metric membrane.hencky_w0 --reference exact
//   mfsi study cavity --vary mesh.refine=0.5,1,2 --vary fluid.convection=upwind,linear
//        --metric fluid.ghia_u_max_err --reference 0
//   mfsi study cavity --vary mesh.refine=1,2,4 --metric fluid.max_velocity --reference finest   # + Richardson
//
// The study is Python's (scripts/study.py: the runs, the table, the fits and the plots); this file
// finds the script, an interpreter with matplotlib and this executable, and hands the command line
// over. Each run is an ordinary `mfsi run` in DIR/runs/<id>/, so a run of a study can be looked at,
// plotted and repeated like any other.
#include "Study.hpp"

#include "Python.hpp"

#include <filesystem>
#include <iostream>

namespace fs = std::filesystem;

int commandStudy(const StudyOptions& o) {
  fs::path script;
  std::string python;
  if (const int code = mfsi::findScriptAndPython("study.py", script, python); code != 0) return code;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) {
    std::cerr << "error: cannot find this executable (/proc/self/exe): " << ec.message() << "\n";
    return 1;
  }
  // Every value as --opt=value: a value starting with '-' (a negative number) stays a value.
  std::vector<std::string> args = {python, script.string(), "--mfsi=" + exe.string()};
  if (o.selfTest) {
    args.push_back("--self-test");
  } else {
    for (const auto& v : o.vary) args.push_back("--vary=" + v);
    for (const auto& s : o.sets) args.push_back("--set=" + s);
    args.push_back("--metric=" + o.metric);
    args.push_back("--reference=" + o.reference);
    args.push_back("--jobs=" + std::to_string(o.jobs));
    if (o.threads > 0) args.push_back("--threads=" + std::to_string(o.threads));
    if (!o.out.empty()) args.push_back("--out=" + o.out);
    args.push_back("--");
    args.push_back(o.scene);
  }
  const int rc = mfsi::runProgram(args, false);
  if (rc == mfsi::kCannotStart) {
    std::cerr << "error: cannot run " << python << " " << script.string() << "\n";
    return 1;
  }
  return rc;
}
