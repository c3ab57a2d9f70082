// Valves on pressure boundaries (the pulsatile pump's inlet and outlet): a valve is open (the
// pressure or resistance condition) while openFrom <= t mod period < openTo and a no-slip wall
// otherwise. A box fed at a constant rate through its left side empties through its right side
// (resistance) in the first half of each second and through its top (fixed pressure) in the second:
// the closed side passes nothing, the open one everything, and the resistance side's pressure is
// C_r q + p0 while open.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/FluidSolver.hpp"
#include "support/Approx.hpp"

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

HexMesh box() {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {6, 3, 3});
  spec.blocks[0].patches = {"left", "right", "bottom", "top", "side", "side"};
  return buildHexMesh(generateBlockMesh(spec));
}

FluidOptions options() {
  FluidOptions o;
  o.viscosity = 0.05;
  o.timeScheme = TimeScheme::BDF2;
  o.boundaries["left"].type = BoundaryType::FlowRate;
  o.boundaries["left"].flowRate = 0.2;
  o.boundaries["right"].type = BoundaryType::Resistance;
  o.boundaries["right"].resistance = 50;
  o.boundaries["right"].pressure = 3;
  o.boundaries["right"].valve = {1.0, 0.0, 0.5};
  o.boundaries["top"].type = BoundaryType::FixedPressure;
  o.boundaries["top"].valve = {1.0, 0.5, 1.0};
  o.boundaries["bottom"].type = BoundaryType::Wall;
  o.boundaries["side"].type = BoundaryType::Wall;
  return o;
}

double patchFlux(const HexMesh& mesh, const FluidSolver& fluid, const char* name) {
  auto phi = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceFlux());
  const auto& p = mesh.patches()[mesh.patchIndex(name)];
  double q = 0;
  for (lid_t f = p.start; f < p.start + p.size; ++f) q += phi(f);
  return q;
}

}  // namespace

TEST(Valves, OutflowSwitchesBetweenTheOpenSides) {
  HexMesh mesh = box();
  FluidSolver fluid(mesh, options());
  const double dt = 0.1, Q = 0.2;
  for (int s = 0; s < 20; ++s) {
    const double t1 = (s + 1) * dt;
    ASSERT_TRUE(fluid.solveStep(s * dt, dt).ok) << "t = " << t1;
    const double tau = std::fmod(t1 + 1e-9, 1.0);
    const bool rightOpen = tau < 0.5;
    const double right = patchFlux(mesh, fluid, "right"), top = patchFlux(mesh, fluid, "top");
    EXPECT_EQ(rightOpen ? top : right, 0.0) << "the closed valve passes nothing at t = " << t1;
    EXPECT_TRUE(near(rightOpen ? right : top, Q, Tol{1e-9, 1e-7}, "the open valve passes the inflow")) << "t = " << t1;
    if (rightOpen) {
      const auto& rp = fluid.boundaryConditions().patches()[mesh.patchIndex("right")];
      EXPECT_TRUE(near(rp.currentPressure, 50 * rp.currentFlowRate + 3, Tol{1e-12, 1e-12}, "p = C_r q + p0"));
      EXPECT_TRUE(near(rp.currentFlowRate, Q, Tol{1e-9, 1e-6}, "q"));
    }
  }
}

TEST(Valves, EveryValveClosedIsAnError) {
  HexMesh mesh = box();
  FluidOptions o = options();
  o.boundaries["top"].valve = {1.0, 0.6, 1.0};  // both closed for 0.5 <= tau < 0.6
  FluidSolver fluid(mesh, o);
  bool thrown = false;
  for (int s = 0; s < 10 && !thrown; ++s) {
    try {
      fluid.solveStep(s * 0.1, 0.1);
    } catch (const InputError& e) {
      thrown = true;
      EXPECT_NE(std::string(e.what()).find("every pressure boundary's valve is closed"), std::string::npos) << e.what();
      EXPECT_EQ(s, 4) << "the step to t = 0.5 (a step takes its conditions at its end; both closed from 0.5)";
    }
  }
  EXPECT_TRUE(thrown);
}
