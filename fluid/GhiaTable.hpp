#pragma once
/// \file
/// \brief Ghia, Ghia & Shin (1982) lid-driven cavity centreline velocities, compiled in so a scene
/// can report its error against them without data files, and the comparison of a cavity solution
/// with them.
#include "fluid/FluidSolver.hpp"

#include <array>
#include <vector>

namespace mfsi::fluid {

/// \brief One tabulated value: u / U_lid on the vertical centreline at height y / L (`uLine`), or
/// v / U_lid on the horizontal centreline at x / L.
struct GhiaPoint {
  bool uLine;
  double coord, value;
};

/// \brief Reynolds numbers with a compiled-in table.
std::vector<int> ghiaReynoldsNumbers();

/// \brief The table at Reynolds number `re` (empty when not compiled in).
const std::vector<GhiaPoint>& ghiaTable(int re);

/// \brief Largest deviation from the table on each centreline, in units of the lid speed.
struct GhiaErrors {
  double uMax = 0;  ///< max over the table's y of |u(x_c, y) / U_lid - u_Ghia|
  double vMax = 0;  ///< max over the table's x of |v(x, y_c) / U_lid - v_Ghia|
  /// The same with linear instead of cubic interpolation between the profile samples, which is how
  /// perf/openfoam/cavity_ghia.py samples OpenFOAM's fields (for like-for-like comparisons).
  double uMaxLinear = 0, vMaxLinear = 0;
  /// Extremes of the interpolated centreline profiles (the same cubic interpolant, sampled every
  /// 1e-4 of the cavity): smooth functionals of the solution, for mesh studies by Richardson
  /// extrapolation where Ghia's table (itself from a 129 x 129 grid) is too coarse a reference.
  double uLineMin = 0, vLineMin = 0, vLineMax = 0;
};

/// \brief Compare a cavity solution with Ghia's table at `re`. The cavity is the bounding box of
/// the mesh in x and y (lid at y max moving in +x with speed `lidSpeed`); the mesh must be a
/// structured block of cell rows and columns (any grading). Centreline profiles are interpolated
/// linearly between the two cell columns (rows) next to the centreline, completed by the wall
/// values, and evaluated at Ghia's points by cubic Lagrange interpolation.
GhiaErrors ghiaErrors(const FluidSolver& fluid, int re, double lidSpeed);

/// \brief The x-y bounding box of the mesh's reference nodes (this rank's part of a decomposed one).
void planeExtent(const HexMesh& mesh, std::array<double, 2>& lo, std::array<double, 2>& hi);

/// \brief The same from cell centroids and velocities (3 per cell, any order: the cells of every
/// rank gathered) and the cavity's extent in x and y.
GhiaErrors ghiaErrors(const std::vector<double>& centroids, const std::vector<double>& velocity,
                      const std::array<double, 2>& lo, const std::array<double, 2>& hi, int re, double lidSpeed);

}  // namespace mfsi::fluid
