// The runaway-growth guard (fluid/RunawayGuard.hpp): the velocity scale a scene prescribes, derived
// by hand for an inlet, a pressure drop alone, a body force and moving walls; the max |U|
// reduction against a host loop; and the check itself on prescribed velocity fields.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/RunawayGuard.hpp"
#include "support/Approx.hpp"
#include "support/FluidCases.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

/// channelBoxMesh(true): 2 x 1 x 0.1, inlet at x = 0 (area 0.1 m^2), outlet at x = 2, walls
/// "bottom" and "lid", empty front and back.
FluidOptions channelOptions() {
  FluidOptions o;
  o.viscosity = 0.01;
  o.boundaries["inlet"].type = BoundaryType::FixedVelocity;
  o.boundaries["outlet"].type = BoundaryType::FixedPressure;
  return o;
}

void fillVelocity(FluidSolver& fluid, Vec3 u) {
  Real3View U("test::U", fluid.mesh().nCells());
  Kokkos::deep_copy(Kokkos::subview(U, Kokkos::ALL(), 0), u[0]);
  Kokkos::deep_copy(Kokkos::subview(U, Kokkos::ALL(), 1), u[1]);
  Kokkos::deep_copy(Kokkos::subview(U, Kokkos::ALL(), 2), u[2]);
  fluid.setVelocity(U);
}

}  // namespace

// Flow-rate inlet Q = 0.15 m^3/s through 0.1 m^2, parabolic across y: mean 1.5 m/s, peak 1.5 x
// 1.5 = 2.25 m/s. A fixed-velocity inlet (0.3, 0.4, 0) under oneMinusCos peaks at 2 x 0.5 = 1 m/s.
TEST(RunawayGuard, TheScaleOfAnInletIsItsPeakVelocity) {
  const HexMesh mesh = test::channelBoxMesh(true);
  {
    FluidOptions o = channelOptions();
    PatchBC& in = o.boundaries["inlet"];
    in.type = BoundaryType::FlowRate;
    in.flowRate = 0.15;
    in.profile = Profile::Parabolic;
    in.parabolicAxes = {false, true, false};
    FluidSolver fluid(mesh, o);
    const PrescribedVelocityScale s = prescribedVelocityScale(fluid);
    EXPECT_TRUE(near(s.boundary, 2.25, Tol{0, 1e-12}));
    EXPECT_EQ(s.initial, 0.0);
    EXPECT_EQ(s.pressure, 0.0);  // one pressure level (the outlet's 0, as the initial pressure)
    EXPECT_EQ(s.gravity, 0.0);
    EXPECT_TRUE(near(s.value(), 2.25, Tol{0, 1e-12}));
  }
  {
    FluidOptions o = channelOptions();
    PatchBC& in = o.boundaries["inlet"];
    in.velocity = {0.3, 0.4, 0.0};
    in.timeFunction.kind = TimeFunction::Kind::OneMinusCos;
    in.timeFunction.period = 2.0;
    o.initialVelocity = {0.0, 0.0, 0.7};
    FluidSolver fluid(mesh, o);
    const PrescribedVelocityScale s = prescribedVelocityScale(fluid);
    EXPECT_TRUE(near(s.boundary, 1.0, Tol{0, 1e-15}));
    EXPECT_TRUE(near(s.initial, 0.7, Tol{0, 1e-15}));
    // At t = 0 the inlet is at rest (1 - cos 0 = 0), yet the scale is the peak: the guard does not
    // stop a flow the initial velocity or a later peak sets in motion.
    EXPECT_EQ(boundaryVelocityNow(fluid), 0.0);
    RunawayGuard guard(fluid, 100);
    EXPECT_TRUE(near(guard.scale(), 1.0, Tol{0, 1e-15}));
  }
}

// Driven by a pressure drop alone: inlet at p = 9 Pa, outlet at 0, rho = 2: sqrt(2 * 9 / 2) = 3 m/s.
// A halfPowerSine pulse on the inlet pressure does not change the range [0, 9]; the initial
// pressure is one of the levels (a pressure of -7 widens the range to 16: sqrt(16) = 4).
TEST(RunawayGuard, TheScaleOfAPressureDropIsSqrtTwoDpOverRho) {
  const HexMesh mesh = test::channelBoxMesh(true);
  FluidOptions o = channelOptions();
  o.density = 2.0;
  o.viscosity = 0.02;
  o.boundaries["inlet"].type = BoundaryType::FixedPressure;
  o.boundaries["inlet"].pressure = 9.0;
  o.boundaries["inlet"].timeFunction.kind = TimeFunction::Kind::HalfPowerSine;
  {
    FluidSolver fluid(mesh, o);
    const PrescribedVelocityScale s = prescribedVelocityScale(fluid);
    EXPECT_EQ(s.boundary, 0.0);  // walls at rest, no velocity inlet
    EXPECT_TRUE(near(s.pressure, 3.0, Tol{0, 1e-15}));
    EXPECT_TRUE(near(s.value(), 3.0, Tol{0, 1e-15}));
  }
  o.initialPressure = -7.0;
  FluidSolver fluid(mesh, o);
  EXPECT_TRUE(near(prescribedVelocityScale(fluid).pressure, 4.0, Tol{0, 1e-15}));
}

// Gravity g = (0, -8, 0) in the 2 x 1 x 0.1 box: L = sqrt(4 + 1 + 0.01), scale sqrt(2 g L). A lid
// wall at (-0.5, 0, 0) under a cosine ramp adds its peak 0.5.
TEST(RunawayGuard, GravityAndWallVelocitiesEnterTheScale) {
  const HexMesh mesh = test::channelBoxMesh(true);
  FluidOptions o = channelOptions();
  o.bodyForce = {0, -8, 0};
  o.boundaries["inlet"].velocity = {0.1, 0, 0};
  o.boundaries["lid"].type = BoundaryType::Wall;
  o.boundaries["lid"].velocity = {-0.5, 0, 0};
  o.boundaries["lid"].timeFunction.kind = TimeFunction::Kind::CosineRamp;
  FluidSolver fluid(mesh, o);
  const PrescribedVelocityScale s = prescribedVelocityScale(fluid);
  EXPECT_TRUE(near(s.gravity, std::sqrt(2 * 8 * std::sqrt(5.01)), Tol{0, 1e-12}));
  EXPECT_TRUE(near(s.boundary, 0.5, Tol{0, 1e-15}));
}

// A baffle membrane (external wall velocity) is the only thing that moves: the scale is what it
// imposes, and it stays the largest seen when the membrane stops (a turning point).
TEST(RunawayGuard, AMembraneWallSetsTheScaleAndItIsKept) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {4, 2, 2});
  spec.blocks[0].patches = {"walls", "walls", "walls", "walls", "walls", "walls"};
  spec.patchKinds = {{"walls", PatchKind::Wall}};
  spec.baffles.push_back({"membrane", 0, 1.0, {0, 0, 0}, {0, 1, 1}});
  const HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.viscosity = 0.01;
  FluidSolver fluid(mesh, o);
  RunawayGuard guard(fluid, 10);
  EXPECT_EQ(guard.prescribed().value(), 0.0);
  const lid_t nb = mesh.patches()[mesh.patchIndex("membrane_master")].size;
  Real3View w("test::wall", nb);
  Kokkos::deep_copy(Kokkos::subview(w, Kokkos::ALL(), 0), 0.2);
  fluid.setWallVelocity("membrane", w);
  EXPECT_TRUE(near(boundaryVelocityNow(fluid), 0.2, Tol{0, 1e-15}));
  fillVelocity(fluid, {0, 1.5, 0});
  EXPECT_NO_THROW(guard.check(fluid, 0.0, 0.1));  // 1.5 < 10 x 0.2
  EXPECT_TRUE(near(guard.scale(), 0.2, Tol{0, 1e-15}));
  Kokkos::deep_copy(w, 0.0);
  fluid.setWallVelocity("membrane", w);
  EXPECT_NO_THROW(guard.check(fluid, 0.1, 0.1));  // the membrane at rest: the scale stays 0.2
  fillVelocity(fluid, {0, 2.5, 0});
  EXPECT_THROW(guard.check(fluid, 0.2, 0.1), DivergenceError);
}

// max |U| is a device reduction: equal to the host loop's value on a non-uniform field.
TEST(RunawayGuard, MaxVelocityMatchesAHostLoop) {
  const HexMesh mesh = test::channelBoxMesh(false);
  FluidSolver fluid(mesh, test::channelFlowOptions(TimeScheme::BDF2));
  const lid_t n = mesh.nCells();
  Real3View U("test::U", n);
  auto h = Kokkos::create_mirror_view(U);
  double expected = 0;
  for (lid_t c = 0; c < n; ++c) {
    for (int k = 0; k < 3; ++k) h(c, k) = std::sin(0.7 * c + 1.3 * k) * (1 + 0.01 * c);
    expected = std::max(expected, std::sqrt(h(c, 0) * h(c, 0) + h(c, 1) * h(c, 1) + h(c, 2) * h(c, 2)));
  }
  Kokkos::deep_copy(U, h);
  fluid.setVelocity(U);
  EXPECT_EQ(maxVelocity(fluid), expected);
}

// The check: quiet up to factor x scale, then a DivergenceError naming max |U|, the scale, the
// time and the remedy; factor 0 is off.
TEST(RunawayGuard, TheCheckNamesTheValueTheScaleTheTimeAndTheRemedy) {
  const HexMesh mesh = test::channelBoxMesh(true);
  FluidOptions o = channelOptions();
  o.boundaries["inlet"].velocity = {2.0, 0, 0};
  FluidSolver fluid(mesh, o);
  RunawayGuard guard(fluid, 100);
  fillVelocity(fluid, {199.0, 0, 0});
  EXPECT_NO_THROW(guard.check(fluid, 1.0, 0.5));
  EXPECT_EQ(guard.lastMaxVelocity(), 199.0);
  fillVelocity(fluid, {0, 201.0, 0});
  try {
    guard.check(fluid, 1.5, 0.5);
    FAIL() << "201 m/s against 100 x 2 m/s passed";
  } catch (const DivergenceError& e) {
    const std::string m = e.what();
    for (const char* part :
         {"max |U| = 201 m/s", "velocity scale 2 m/s", "t = 2", "divergenceVelocityFactor = 100", "reduce time.dt"})
      EXPECT_NE(m.find(part), std::string::npos) << "'" << part << "' not in: " << m;
  }
  RunawayGuard off(fluid, 0);
  fillVelocity(fluid, {1e20, 0, 0});
  EXPECT_NO_THROW(off.check(fluid, 2.0, 0.5));
}
