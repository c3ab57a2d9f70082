// Space conservation through the whole coupling loop: a uniform flow U = (1, 0, 0) through a channel
// with slip walls, and inside it a thin plate (a baffle carried by a rigid body) that the body moves
// downstream at exactly U. The orchestrator moves the plate, the mesh motion shears the cells around
// it, the fluid solves on the moving mesh with the plate's walls at the mesh velocity: the uniform
// flow is an exact solution, and the discrete one must keep it to round-off (swept volumes, BDF2
// mesh fluxes and moving walls consistent with each other, step after step).
#include "coupling/Module.hpp"
#include "coupling/Simulation.hpp"
#include "coupling/orchestrator/FsiCoupling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

TEST(SpaceConservation, UniformFlowStaysUniformAroundAPlateTheCouplingMoves) {
  const std::string yaml =
      "name: moving-plate\n"
      "time: {endTime: 0.2, dt: 0.02}\n"
      "mesh:\n"
      "  blocks:\n"
      "    - {min: [0, 0, 0], max: [4, 1, 1], cells: [32, 8, 8],\n"
      "       patches: {xmin: inlet, xmax: outlet, ymin: walls, ymax: walls, zmin: walls, zmax: walls}}\n"
      "  baffles:\n"
      "    - {name: plate, axis: y, position: 0.5, min: [1, 0.5, 0.25], max: [2, 0.5, 0.75]}\n"
      "  patchTypes: {walls: wall}\n"
      "fluid:\n"
      "  density: 1\n"
      "  viscosity: 0.01\n"
      "  timeScheme: bdf2\n"
      "  initial: {velocity: [1, 0, 0]}\n"
      "  pimple: {outerCorrectors: 3, correctors: 2, nonOrthogonalCorrectors: 1}\n"
      "  solvers:\n"
      "    pressure: {tolerance: 1.0e-14, relTol: 0}\n"
      "    momentum: {tolerance: 1.0e-14, relTol: 0}\n"
      "  boundary:\n"
      "    inlet: {type: fixedVelocity, velocity: [1, 0, 0]}\n"
      "    outlet: {type: fixedPressure, pressure: 0}\n"
      "    walls: {type: slip}\n"
      "    plate: {type: movingWall}\n"
      "bodies:\n"
      "  members:\n"
      "    carrier:\n"
      "      mass: 1\n"
      "      joint: {type: prescribed, axes: [Px], motion: [{type: linear, value: 0, rate: 1}]}\n"
      "coupling:\n"
      "  bodyPatches: {carrier: [plate]}\n";
  auto cfg = mfsi::SceneConfig::fromString(yaml, "moving-plate.yaml", mfsi::sceneSchema(), {});
  mfsi::Simulation sim(cfg);
  const std::string dir = ::testing::TempDir() + "/space_conservation";
  std::filesystem::create_directories(dir);
  const auto r = sim.run(dir, false);
  mfsi::FsiCoupling* fsi = nullptr;
  for (const auto& m : sim.modules())
    if (auto* c = dynamic_cast<mfsi::FsiCoupling*>(m.get())) fsi = c;
  ASSERT_NE(fsi, nullptr);
  const auto& fluid = fsi->fluid().solver();
  auto U = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), fluid.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), fluid.pressure());
  auto X = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), sim.mesh().referencePoints());
  auto x = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), sim.mesh().points());
  double dev = 0, pmax = 0, moved = 0;
  for (int c = 0; c < static_cast<int>(U.extent(0)); ++c) {
    dev = std::max({dev, std::abs(U(c, 0) - 1), std::abs(U(c, 1)), std::abs(U(c, 2))});
    pmax = std::max(pmax, std::abs(p(c)));
  }
  for (int v = 0; v < static_cast<int>(X.extent(0)); ++v) moved = std::max(moved, std::abs(x(v, 0) - X(v, 0)));
  std::printf("plate moved %.4f m; max |U - (1,0,0)| = %.3e, max |p| = %.3e, min scaled Jacobian %.3f\n", moved, dev,
              pmax, r.metrics.at("coupling.min_scaled_jacobian"));
  EXPECT_NEAR(moved, 0.2, 1e-12) << "the plate is where its body puts it";
  EXPECT_LT(r.metrics.at("coupling.min_scaled_jacobian"), 0.99) << "the cells really shear";
  EXPECT_LT(dev, 1e-10);
  EXPECT_LT(pmax, 1e-10);
}
