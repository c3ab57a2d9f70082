#pragma once
// A transient 3D lid-driven cube cavity scene (Re 100, BDF2, two correctors; the AMG on a
// lattice): small, fast, and exercising the fluid's whole state, for tests of whole runs.
#include <string>

namespace mfsi::test {

inline std::string cubeCavityScene(int cells, double endTime) {
  const std::string n = std::to_string(cells);
  return "name: cavity3d\n"
         "time: {endTime: " + std::to_string(endTime) + ", dt: 0.02}\n"
         "mesh:\n"
         "  blocks:\n"
         "    - min: [0, 0, 0]\n"
         "      max: [1, 1, 1]\n"
         "      cells: [" + n + ", " + n + ", " + n + "]\n"
         "      patches: {xmin: walls, xmax: walls, ymin: walls, ymax: lid, zmin: walls, zmax: walls}\n"
         "  patchTypes: {walls: wall, lid: wall}\n"
         "fluid:\n"
         "  nu: 0.01\n"
         "  timeScheme: bdf2\n"
         "  pimple: {outerCorrectors: 1, correctors: 2}\n"
         "  solvers:\n"
         "    pressure: {tolerance: 1.0e-8, relTol: 0.01, preconditionerRefresh: 7}\n"
         "  boundary:\n"
         "    lid: {type: wall, velocity: [1, 0, 0]}\n";
}

}  // namespace mfsi::test
