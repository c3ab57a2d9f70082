// Boundary conditions and loads: input checks, time functions, slip walls, a static baffle with
// hydrostatic pressure on both sides (net pressure, force and moment), and a lid driven by a time
// function.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/Loads.hpp"
#include "support/Approx.hpp"

#include <cmath>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kPi = 3.14159265358979323846;

HexMesh duct(std::array<int, 3> n, bool baffle) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, n);
  spec.blocks[0].patches = {"left", "right", "side", "side", "side", "side"};
  if (baffle) spec.baffles.push_back({"membrane", 0, 1.0, {0, 0, 0}, {0, 1, 1}});
  return buildHexMesh(generateBlockMesh(spec));
}

}  // namespace

TEST(FluidBoundaryConditions, InputErrorsNameThePatch) {
  HexMesh mesh = duct({4, 2, 2}, false);
  FluidOptions o;
  o.boundaries["left"].type = BoundaryType::FixedVelocity;
  o.boundaries["side"].type = BoundaryType::Wall;
  // "right" is a plain patch without a condition.
  try {
    FluidSolver f(mesh, o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("right"), std::string::npos) << e.what();
  }
  o.boundaries["rigth"].type = BoundaryType::FixedPressure;
  EXPECT_THROW(FluidSolver(mesh, o), InputError);
  o.boundaries.erase("rigth");
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  FluidSolver ok(mesh, o);
  Real3View v("test::v", 3);
  EXPECT_THROW(ok.setWallVelocity("side", v), InputError);  // not an external-motion wall
  EXPECT_THROW(ok.setWallVelocity("nothing", v), InputError);
  o.density = -1;
  EXPECT_THROW(FluidSolver(mesh, o), InputError);
}

TEST(FluidBoundaryConditions, TimeFunctions) {
  TimeFunction f;
  EXPECT_EQ(f(3.0), 1.0);
  f.kind = TimeFunction::Kind::OneMinusCos;
  f.period = 5.0;
  EXPECT_TRUE(near(f(1.25), 1.0, Tol{1e-15, 0}));
  EXPECT_TRUE(near(f(2.5), 2.0, Tol{1e-15, 0}));
  f.kind = TimeFunction::Kind::CosineRamp;
  f.period = 2.0;
  EXPECT_TRUE(near(f(1.0), 0.5, Tol{1e-15, 0}));
  EXPECT_EQ(f(2.5), 1.0);
  f.kind = TimeFunction::Kind::Function;
  f.fn = [](real t) { return 3 * t; };
  EXPECT_EQ(f(2.0), 6.0);
}

TEST(FluidBoundaryConditions, LidVelocityFollowsItsTimeFunction) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 0.25}, {4, 4, 1});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "fb", "fb"};
  spec.patchKinds = {{"walls", PatchKind::Wall}, {"fb", PatchKind::Empty}};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  PatchBC lid;
  lid.type = BoundaryType::Wall;
  lid.velocity = {1, 0, 0};
  lid.timeFunction.kind = TimeFunction::Kind::OneMinusCos;
  lid.timeFunction.period = 5.0;
  o.boundaries["lid"] = lid;
  FluidSolver fluid(mesh, o);
  const double t = 0.3, dt = 0.1;
  ASSERT_TRUE(fluid.solveStep(t, dt).ok);
  auto ub = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.boundaryVelocity());
  const auto& p = mesh.patches()[mesh.patchIndex("lid")];
  const double expected = 1.0 - std::cos(2 * kPi * (t + dt) / 5.0);
  for (int f = p.start; f < p.start + p.size; ++f) {
    const int b = f - mesh.nInternalFaces();
    EXPECT_TRUE(near(ub(b, 0), expected, Tol{1e-15, 1e-14}, "lid u"));
    EXPECT_TRUE(near(ub(b, 1), 0.0, Tol{1e-15, 0}, "lid v (impermeable)"));
  }
  // The fluid below the lid is dragged along +x.
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  EXPECT_GT(U(own(p.start), 0), 0.0);
}

TEST(FluidBoundaryConditions, SlipWallsKeepAPlugFlow) {
  HexMesh mesh = duct({6, 3, 3}, false);
  FluidOptions o;
  o.viscosity = 0.1;
  o.timeScheme = TimeScheme::Euler;
  o.pimple.nOuterCorrectors = 3;
  o.initialVelocity = {0.7, 0, 0};
  o.boundaries["left"].type = BoundaryType::FixedVelocity;
  o.boundaries["left"].velocity = {0.7, 0, 0};
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  o.boundaries["side"].type = BoundaryType::Slip;
  FluidSolver fluid(mesh, o);
  for (int s = 0; s < 3; ++s) ASSERT_TRUE(fluid.solveStep(0.1 * s, 0.1).ok);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  for (int c = 0; c < mesh.nCells(); ++c) {
    ASSERT_TRUE(near(U(c, 0), 0.7, Tol{1e-12, 0}, "u"));
    ASSERT_TRUE(near(U(c, 1), 0.0, Tol{1e-12, 0}, "v"));
    ASSERT_TRUE(near(p(c), 0.0, Tol{1e-12, 0}, "p"));
  }
}

TEST(FluidBoundaryConditions, StaticBaffleCarriesTheHydrostaticPressureJump) {
  // Fluid at rest in a duct split by a membrane at x = 1; open ends at p1 and p2; gravity along x.
  // Each side is hydrostatic, p = p_end + rho g (x - x_end), so across the membrane
  // pNet = p_left(1) - p_right(1) = p1 - p2 + 2 rho g.
  const double rho = 1.2, g = -9.81, p1 = 30.0, p2 = 10.0;
  HexMesh mesh = duct({6, 2, 2}, true);
  FluidOptions o;
  o.density = rho;
  o.viscosity = 0.01;
  o.bodyForce = {g, 0, 0};
  o.timeScheme = TimeScheme::Steady;
  o.pimple.nOuterCorrectors = 100;
  o.pimple.relaxVelocity = 0.8;
  o.pimple.relaxPressure = 0.5;
  o.pimple.outerTolerance = 1e-11;
  o.boundaries["left"].type = BoundaryType::FixedPressure;
  o.boundaries["left"].pressure = p1;
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  o.boundaries["right"].pressure = p2;
  o.boundaries["side"].type = BoundaryType::Wall;
  FluidSolver fluid(mesh, o);
  const auto r = fluid.solveStep(0.0, 1.0);
  // (At rest the scaled momentum residual is round-off over round-off and never drops below
  // ~1e-7, so the outer loop runs to its limit; the pressure residual is the meaningful one.)
  ASSERT_TRUE(r.ok);
  EXPECT_LT(r.finalPressureResidual, 1e-9);
  const int nb = mesh.patches()[mesh.patchIndex("membrane_master")].size;
  RealView pNet("test::pNet", nb);
  baffleNetPressure(fluid, "membrane", pNet);
  auto hp = Kokkos::create_mirror_view_and_copy(HostSpace(), pNet);
  const double expected = p1 - p2 + 2 * rho * g;
  for (int i = 0; i < nb; ++i) EXPECT_TRUE(near(hp(i), expected, Tol{1e-8, 1e-9}, "pNet"));
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  for (int c = 0; c < mesh.nCells(); ++c)
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(near(U(c, k), 0.0, Tol{1e-8, 0}, "fluid at rest"));
  // Net force and moment on the membrane (area 1, centroid (1, 0.5, 0.5)).
  const auto L = patchLoads(fluid, "membrane", {0, 0, 0});
  EXPECT_TRUE(near(L.area, 2.0, Tol{1e-14, 0}, "both sides' area"));
  EXPECT_TRUE(near(L.pressureForce[0], expected, Tol{1e-8, 1e-9}, "Fx"));
  EXPECT_TRUE(near(L.pressureForce[1], 0.0, Tol{1e-8, 0}, "Fy"));
  EXPECT_TRUE(near(L.moment[0], 0.0, Tol{1e-8, 0}, "Mx"));
  EXPECT_TRUE(near(L.moment[1], 0.5 * expected, Tol{1e-8, 1e-9}, "My"));
  EXPECT_TRUE(near(L.moment[2], -0.5 * expected, Tol{1e-8, 1e-9}, "Mz"));
  // Per-face traction on one side: pressure part p n, no viscous part at rest.
  const auto& pm = mesh.patches()[mesh.patchIndex("membrane_master")];
  Real3View tp("test::tp", pm.size), tv("test::tv", pm.size);
  boundaryTraction(fluid, "membrane_master", tp, tv);
  auto htp = Kokkos::create_mirror_view_and_copy(HostSpace(), tp);
  auto htv = Kokkos::create_mirror_view_and_copy(HostSpace(), tv);
  for (int i = 0; i < pm.size; ++i) {
    EXPECT_TRUE(near(htp(i, 0), p1 + rho * g, Tol{1e-8, 1e-9}, "master-side pressure"));
    EXPECT_TRUE(near(htv(i, 0), 0.0, Tol{1e-8, 0}, "viscous traction at rest"));
  }
}
