#pragma once
// `mfsi study`: what accuracy costs in time — a scene run over a grid of settings, drawn by
// scripts/study.py.

#include <string>
#include <vector>

/// \brief What `mfsi study` was asked (its command line, unchecked: scripts/study.py checks it).
struct StudyOptions {
  std::string scene;              ///< scene file or built-in scene name
  std::vector<std::string> vary;  ///< KEY=V1,V2,... (KEY1+KEY2=... sets both to each value)
  std::vector<std::string> sets;  ///< KEY=VALUE given to every run
  std::string metric;             ///< summary.json metric compared with the reference
  std::string reference;          ///< exact | exact:KEY | finest | a number
  std::string out;                ///< study folder (empty: results/<scene>-study)
  int jobs = 1;                   ///< runs at once
  int threads = 0;                ///< threads of the whole study (0: OMP_NUM_THREADS or all cores)
  bool selfTest = false;          ///< check the script's fits and exit
};

/// \brief `mfsi study SCENE --vary KEY=V1,V2,... --metric NAME --reference R [--jobs K] [--out DIR]`:
/// runs scripts/study.py with an interpreter that has matplotlib (as `mfsi plot` finds it), which runs
/// `mfsi run` (this executable) once per setting of the grid and writes DIR/study.csv, DIR/study.json
/// and PNGs of error against wall time (Pareto front) and against resolution (observed order).
/// Called before MPI and Kokkos are initialised: the runs are separate processes.
/// \return the script's exit code: 0 ok (failed runs are rows), 2 bad input or no interpreter with
/// matplotlib, 130 / 143 interrupted by SIGINT / SIGTERM (what is done is written; run the same
/// command again to continue), 1 the script could not run or failed.
int commandStudy(const StudyOptions& options);
