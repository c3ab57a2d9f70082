#pragma once
// `mfsi plot`: PNG pictures of a run folder, drawn by scripts/plot_run.py with matplotlib.

#include <string>

/// \brief `mfsi plot RUN_DIR [--out DIR]`: runs scripts/plot_run.py on a folder written by
/// `mfsi run`, which writes PNGs of steps.csv's time series grouped by quantity, of each rigid body
/// in bodies.csv and, for a 2D scene, of p and |U| at the last field output, into `outDir`
/// (empty: RUN_DIR/plots) and prints their names.
///
/// The interpreter is the first that can import matplotlib of: $MFSI_PLOT_PYTHON when set (then
/// the only one tried), the one CMake found at configure time, /usr/bin/python3, python3 on PATH.
/// \return 0 ok; 2 bad input (not a run folder, nothing to plot) or no interpreter with
/// matplotlib; 4 a picture could not be written; 1 the script could not run or failed; 128 + N
/// the script was ended by signal N.
int commandPlot(const std::string& runDir, const std::string& outDir);
