#pragma once
// Meshes and flow set-ups shared by the fluid tests.
#include "core/BlockMesh.hpp"
#include "fluid/FluidOptions.hpp"

namespace mfsi::test {

/// Unit cube of n^3 cells, walls all round; the y = 1 side is the patch "lid" (3D lid-driven
/// cavity: give it a wall velocity).
inline HexMesh cubeCavityMesh(int n) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "walls", "walls"};
  spec.patchKinds = {{"walls", PatchKind::Wall}, {"lid", PatchKind::Wall}};
  return buildHexMesh(generateBlockMesh(spec));
}

/// Graded channel box 2 x 1 x 0.6 (8 x 5 x 4 cells): "inlet" x-, "outlet" x+, "bottom" and "lid"
/// walls, z sides "sides" as slip planes; with twoD one cell thick (0.1) with empty sides.
inline HexMesh channelBoxMesh(bool twoD = false) {
  auto spec = boxSpec({0, 0, 0}, {2.0, 1.0, twoD ? 0.1 : 0.6}, {8, 5, twoD ? 1 : 4});
  spec.blocks[0].grading = {1.5, 0.8, 1.0};
  spec.blocks[0].patches = {"inlet", "outlet", "bottom", "lid", "sides", "sides"};
  spec.patchKinds = {{"bottom", PatchKind::Wall},
                     {"lid", PatchKind::Wall},
                     {"sides", twoD ? PatchKind::Empty : PatchKind::Symmetry}};
  return buildHexMesh(generateBlockMesh(spec));
}

/// Flow through channelBoxMesh exercising every boundary kind of the fused passes: inflow
/// (1, 0.2, 0), outlet at p = 0.5, lid sliding at -0.5, a body force; 2 outer and 2 pressure
/// correctors, solver tolerances 1e-12.
inline fluid::FluidOptions channelFlowOptions(fluid::TimeScheme time) {
  fluid::FluidOptions o;
  o.viscosity = 0.02;
  o.timeScheme = time;
  o.bodyForce = {0.1, -0.3, 0.0};
  o.pimple.nOuterCorrectors = 2;
  o.pimple.nCorrectors = 2;
  o.momentumSolver = {1e-12, 0.0, 500};
  o.pressureSolver = {1e-12, 0.0, 500};
  o.boundaries["inlet"].type = fluid::BoundaryType::FixedVelocity;
  o.boundaries["inlet"].velocity = {1.0, 0.2, 0.0};
  o.boundaries["outlet"].type = fluid::BoundaryType::FixedPressure;
  o.boundaries["outlet"].pressure = 0.5;
  o.boundaries["lid"].type = fluid::BoundaryType::Wall;
  o.boundaries["lid"].velocity = {-0.5, 0.0, 0.0};
  return o;
}

}  // namespace mfsi::test
