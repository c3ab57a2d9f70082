#pragma once
/// \file
/// \brief The meshes and options of the distributed fluid tests (tests/mpi/test_distributed_fluid_np*.cpp):
/// a lid-driven 3D cavity (pressure level pinned at one cell, so one rank holds the pin), the same
/// cavity on a mesh with distorted interior nodes (non-orthogonal corrections and the velocity
/// gradient cross rank boundaries), and the unstructured, graded Gmsh cylinder mesh (inlet,
/// fixed-pressure outlet).
#include "core/BlockMesh.hpp"
#include "core/GmshReader.hpp"
#include "fluid/FluidOptions.hpp"

#include <cmath>
#include <string>

namespace mfsi::test {

/// A unit cube of n^3 cells whose y = 1 side is the lid; `distortion` > 0 moves the interior
/// nodes by up to that fraction of a cell.
inline HexMeshInput cavityCube(int n, double distortion = 0.0) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "walls", "walls"};
  spec.patchKinds = {{"walls", PatchKind::Wall}};
  HexMeshInput in = generateBlockMesh(spec);
  if (distortion > 0) {
    const double h = 1.0 / n, pi = 3.14159265358979323846;
    for (auto& x : in.points) {
      bool interior = true;
      for (int d = 0; d < 3; ++d) interior = interior && x[d] > 0.5 * h && x[d] < 1 - 0.5 * h;
      if (!interior) continue;
      const double X = x[0], Y = x[1], Z = x[2];
      x[0] += distortion * h * std::sin(2 * pi * Y) * std::sin(3 * pi * Z);
      x[1] += distortion * h * std::sin(3 * pi * X) * std::sin(2 * pi * Z);
      x[2] += distortion * h * std::sin(2 * pi * X) * std::sin(3 * pi * Y);
    }
  }
  return in;
}

/// BDF2 PIMPLE with tight linear solves, so that fields from different summation orders and
/// preconditioners agree to ~1e-12.
inline fluid::FluidOptions tightOptions() {
  fluid::FluidOptions o;
  o.viscosity = 0.01;
  o.timeScheme = fluid::TimeScheme::BDF2;
  o.pimple.nOuterCorrectors = 3;
  o.pimple.nCorrectors = 2;
  o.momentumSolver = {1e-14, 0.0, 1000};
  o.pressureSolver = {1e-14, 0.0, 2000};
  o.pressureFinalRelTol = -1;
  return o;
}

inline fluid::FluidOptions cavityOptions(int nonOrthogonalCorrectors = 0) {
  fluid::FluidOptions o = tightOptions();
  o.pimple.nNonOrthogonalCorrectors = nonOrthogonalCorrectors;
  fluid::PatchBC lid;
  lid.type = fluid::BoundaryType::Wall;
  lid.velocity = {1, 0, 0};
  o.boundaries["lid"] = lid;
  return o;
}

inline HexMeshInput gradedCylinder() {
  return readGmsh(std::string(MFSI_TEST_DATA_DIR) + "/meshes/cylinder_graded.msh");
}

inline fluid::FluidOptions cylinderOptions() {
  fluid::FluidOptions o = tightOptions();
  o.viscosity = 1e-3;
  o.pimple.nNonOrthogonalCorrectors = 1;
  fluid::PatchBC in;
  in.type = fluid::BoundaryType::FixedVelocity;
  in.velocity = {0.3, 0, 0};
  in.profile = fluid::Profile::Parabolic;
  in.parabolicAxes = {false, true, false};
  o.boundaries["inlet"] = in;
  o.boundaries["outlet"].type = fluid::BoundaryType::FixedPressure;
  o.boundaries["walls"].type = fluid::BoundaryType::Wall;
  o.boundaries["cylinder"].type = fluid::BoundaryType::Wall;
  o.boundaries["frontAndBack"].type = fluid::BoundaryType::Empty;
  return o;
}

}  // namespace mfsi::test
