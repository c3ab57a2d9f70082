// ALE verification: discrete space conservation (uniform flow stays uniform on a randomly moving
// mesh), continuity at solver tolerance on a moving mesh, walls that move with the mesh, and a
// moving baffle (membrane) driven through the FSI-facing API.
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/Loads.hpp"
#include "support/Approx.hpp"
#include "support/FluidCases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Interior nodes of a box oscillate with random amplitudes and phases (boundary nodes fixed).
MeshMotion randomInteriorMotion(const HexMesh& mesh, double amplitude, double omega, unsigned seed) {
  auto ref = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  std::vector<std::array<double, 3>> amp(mesh.nNodes()), phase(mesh.nNodes());
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int n = 0; n < mesh.nNodes(); ++n)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], ref(n, k));
      hi[k] = std::max(hi[k], ref(n, k));
    }
  for (int n = 0; n < mesh.nNodes(); ++n) {
    bool interior = true;
    for (int k = 0; k < 3; ++k) interior = interior && ref(n, k) > lo[k] + 1e-9 && ref(n, k) < hi[k] - 1e-9;
    for (int k = 0; k < 3; ++k) {
      amp[n][k] = interior ? amplitude * u(gen) : 0.0;
      phase[n][k] = kPi * u(gen);
    }
  }
  return [ref, amp, phase, omega](real t, const Real3View& pts) {
    auto h = Kokkos::create_mirror_view(pts);
    for (std::size_t n = 0; n < amp.size(); ++n)
      for (int k = 0; k < 3; ++k) h(n, k) = ref(n, k) + amp[n][k] * std::sin(omega * t + phase[n][k]);
    Kokkos::deep_copy(pts, h);
  };
}

HexMesh box(std::array<int, 3> n) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, n);
  spec.blocks[0].patches = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  return buildHexMesh(generateBlockMesh(spec));
}

}  // namespace

TEST(MovingMesh, UniformFlowStaysUniformOnRandomlyMovingMesh) {
  for (TimeScheme scheme : {TimeScheme::Euler, TimeScheme::BDF2}) {
    HexMesh mesh = box({6, 5, 4});
    const Vec3 U0{1.0, 0.5, -0.25};
    FluidOptions o;
    o.viscosity = 0.05;
    o.timeScheme = scheme;
    o.initialVelocity = U0;
    o.pimple.nOuterCorrectors = 2;
    o.pimple.nCorrectors = 2;
    o.pimple.nNonOrthogonalCorrectors = 1;
    for (const char* name : {"xmin", "ymin", "ymax", "zmin", "zmax"}) {
      PatchBC in;
      in.type = BoundaryType::FixedVelocity;
      in.velocity = U0;
      o.boundaries[name] = in;
    }
    PatchBC out;
    out.type = BoundaryType::FixedPressure;
    o.boundaries["xmax"] = out;
    FluidSolver fluid(mesh, o);
    fluid.setMeshMotion(randomInteriorMotion(mesh, 0.25 / 6, 2 * kPi, 7));
    double maxDev = 0, maxP = 0, maxMeshFlux = 0;
    for (int step = 0; step < 8; ++step) {
      const auto r = fluid.solveStep(step * 0.05, 0.05);
      ASSERT_TRUE(r.ok);
      auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
      auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
      for (int c = 0; c < mesh.nCells(); ++c) {
        for (int k = 0; k < 3; ++k) maxDev = std::max(maxDev, std::abs(U(c, k) - U0[k]));
        maxP = std::max(maxP, std::abs(p(c)));
      }
      auto mp = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.meshFlux());
      for (int f = 0; f < mesh.nFaces(); ++f) maxMeshFlux = std::max(maxMeshFlux, std::abs(mp(f)));
    }
    std::printf("%s: max |U - U0| = %.3e, max |p| = %.3e, max |mesh flux| = %.3e\n", toString(scheme), maxDev, maxP,
                maxMeshFlux);
    EXPECT_GT(maxMeshFlux, 1e-3);  // the mesh really moves
    EXPECT_LT(maxDev, 1e-12);
    EXPECT_LT(maxP, 1e-12);
  }
}

TEST(MovingMesh, ContinuityHoldsToSolverToleranceOnMovingMesh) {
  HexMesh mesh = box({6, 6, 3});
  FluidOptions o;
  o.viscosity = 0.02;
  o.pimple.nOuterCorrectors = 1;
  o.pimple.nCorrectors = 2;
  o.pressureSolver = {1e-12, 0.0, 5000};
  PatchBC in;
  in.type = BoundaryType::FixedVelocity;
  in.velocity = {1.0, 0, 0};
  in.profile = Profile::Parabolic;
  in.parabolicAxes = {false, true, true};
  o.boundaries["xmin"] = in;
  PatchBC out;
  out.type = BoundaryType::FixedPressure;
  o.boundaries["xmax"] = out;
  for (const char* name : {"ymin", "ymax", "zmin", "zmax"}) o.boundaries[name].type = BoundaryType::Wall;
  FluidSolver fluid(mesh, o);
  fluid.setMeshMotion(randomInteriorMotion(mesh, 0.2 / 6, 3.0, 11));
  double inflow = 0;
  {
    auto phi = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceFlux());
    const auto& p = mesh.patches()[mesh.patchIndex("xmin")];
    for (int f = p.start; f < p.start + p.size; ++f) inflow -= phi(f);
  }
  ASSERT_GT(inflow, 0.1);
  for (int step = 0; step < 6; ++step) {
    const auto r = fluid.solveStep(step * 0.1, 0.1);
    ASSERT_TRUE(r.ok);
    // |sum_f phi_f| summed over cells is the L1 norm of the last pressure residual.
    EXPECT_LT(r.continuitySum, 1e-9 * inflow) << "step " << step;
  }
}

TEST(MovingMesh, PistonWallMovingWithTheMeshDrivesUniformFlow) {
  // Closed-bottom column: the bottom wall moves with the mesh (the mesh stretches linearly in z),
  // the top is an outlet. The exact solution is a uniform vertical velocity equal to the piston's,
  // and dp/dz = -rho dw/dt.
  const double rho = 2.0, a = 0.1, omega = 2.0, dt = 0.01;
  auto spec = boxSpec({0, 0, 0}, {1, 1, 2}, {2, 2, 8});
  spec.blocks[0].patches = {"side", "side", "side", "side", "piston", "top"};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.density = rho;
  o.viscosity = 0.01;
  o.timeScheme = TimeScheme::BDF2;
  o.pimple.nOuterCorrectors = 20;
  o.pimple.outerTolerance = 1e-11;
  o.boundaries["side"].type = BoundaryType::Slip;
  o.boundaries["piston"].type = BoundaryType::Wall;
  o.boundaries["piston"].wallMotion = WallMotion::MeshVelocity;
  o.boundaries["top"].type = BoundaryType::FixedPressure;
  FluidSolver fluid(mesh, o);
  auto ref = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  auto zb = [&](double t) { return a * std::sin(omega * t); };
  fluid.setMeshMotion([&](real t, const Real3View& pts) {
    auto h = Kokkos::create_mirror_view(pts);
    for (int n = 0; n < mesh.nNodes(); ++n) {
      h(n, 0) = ref(n, 0);
      h(n, 1) = ref(n, 1);
      h(n, 2) = zb(t) + ref(n, 2) * (2.0 - zb(t)) / 2.0;
    }
    Kokkos::deep_copy(pts, h);
  });
  double t = 0;
  for (int step = 0; step < 40; ++step, t += dt) {
    const auto r = fluid.solveStep(t, dt);
    ASSERT_TRUE(r.ok);
  }
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  const double w = a * omega * std::cos(omega * t), dwdt = -a * omega * omega * std::sin(omega * t);
  for (int c = 0; c < mesh.nCells(); ++c) {
    ASSERT_TRUE(near(U(c, 2), U(0, 2), Tol{1e-10, 0}, "uniform w"));
    ASSERT_TRUE(near(U(c, 0), 0.0, Tol{1e-10, 0}, "u"));
    ASSERT_TRUE(near(U(c, 1), 0.0, Tol{1e-10, 0}, "v"));
  }
  EXPECT_TRUE(near(U(0, 2), w, Tol{0, 1e-3}, "piston velocity"));
  // Pressure: linear in z, p(top) = 0, slope -rho dw/dt.
  for (int c = 0; c < mesh.nCells(); ++c)
    ASSERT_TRUE(near(p(c), -rho * dwdt * (C(c, 2) - 2.0), Tol{2e-3 * rho * std::abs(dwdt), 0.01}, "pressure"));
}

TEST(MovingMesh, OscillatingBaffleLoadsMatchTheAddedMassOfTheColumns) {
  // A membrane (baffle at x = X(t)) across a duct [0, 2] x [0, 1]^2 with open ends (p = 0). The
  // fluid on both sides moves rigidly with the membrane, so the net pressure on it is the inertia of
  // the two unit-length columns: pNet = p_left - p_right = -2 rho dw/dt.
  const double rho = 1.5, a = 0.1, omega = 3.0, dt = 0.005;
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {8, 2, 2});
  spec.blocks[0].patches = {"left", "right", "side", "side", "side", "side"};
  spec.baffles.push_back({"membrane", 0, 1.0, {0, 0, 0}, {0, 1, 1}});
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.density = rho;
  o.viscosity = 0.01;
  o.pimple.nOuterCorrectors = 2;
  o.boundaries["left"].type = BoundaryType::FixedPressure;
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  o.boundaries["side"].type = BoundaryType::Slip;
  FluidSolver fluid(mesh, o);
  const int nb = mesh.patches()[mesh.patchIndex("membrane_master")].size;
  ASSERT_EQ(nb, 4);
  auto ref = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  auto X = [&](double t) { return 1.0 + a * std::sin(omega * t); };
  Real3View pts("test::points", mesh.nNodes());
  Real3View wallVel("test::membraneVelocity", nb);
  RealView pNet("test::pNet", nb);
  double t = 0;
  for (int step = 0; step < 60; ++step, t += dt) {
    fluid.beginStep(t, dt);
    auto h = Kokkos::create_mirror_view(pts);
    const double xb = X(t + dt);
    for (int n = 0; n < mesh.nNodes(); ++n) {
      const double x = ref(n, 0);
      h(n, 0) = x <= 1.0 ? x * xb : xb + (x - 1.0) * (2.0 - xb);
      h(n, 1) = ref(n, 1);
      h(n, 2) = ref(n, 2);
    }
    Kokkos::deep_copy(pts, h);
    // Two "FSI iterations": the second must reproduce the first (same motion, warm start).
    for (int it = 0; it < 2; ++it) {
      fluid.moveMesh(pts);
      Kokkos::deep_copy(wallVel, 0.0);  // tangential membrane velocity; the normal one comes from the mesh
      fluid.setWallVelocity("membrane", wallVel);
      ASSERT_TRUE(fluid.solve().ok);
    }
  }
  baffleNetPressure(fluid, "membrane", pNet);
  auto hp = Kokkos::create_mirror_view_and_copy(HostSpace(), pNet);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  const double w = a * omega * std::cos(omega * t), dwdt = -a * omega * omega * std::sin(omega * t);
  for (int c = 0; c < mesh.nCells(); ++c) ASSERT_TRUE(near(U(c, 0), w, Tol{0, 2e-3}, "rigid column velocity"));
  for (int i = 0; i < nb; ++i) EXPECT_TRUE(near(hp(i), -2.0 * rho * dwdt, Tol{0, 0.02}, "pNet"));
  const auto loads = patchLoads(fluid, "membrane");
  EXPECT_TRUE(near(loads.pressureForce[0], -2.0 * rho * dwdt * 1.0, Tol{0, 0.02}, "net membrane force"));
}

TEST(MovingMesh, ASolveFromTheRestoredStepStartRepeatsTheFirstSolve) {
  // What a coupling that re-solves a step needs: after other solves on other meshes, restoring
  // the step's start and solving on the first mesh again gives the first answer bit for bit. Without
  // the restore the solve continues from the last answer (2 outer correctors do not converge the
  // step), and the answer differs: the restore is what makes it repeat.
  HexMesh mesh = mfsi::test::channelBoxMesh();
  FluidSolver fluid(mesh, mfsi::test::channelFlowOptions(TimeScheme::BDF2));
  const MeshMotion motion = randomInteriorMotion(mesh, 0.03, 2.0, 7);
  Real3View pts("test::points", mesh.nNodes()), other("test::other", mesh.nNodes());
  const double dt = 0.05;
  for (int s = 0; s < 3; ++s) {
    fluid.beginStep(s * dt, dt);
    motion((s + 1) * dt, pts);
    fluid.moveMesh(pts);
    fluid.solve();
  }
  fluid.keepStepStart(true);
  fluid.beginStep(3 * dt, dt);
  motion(4 * dt, pts);
  motion(4.5 * dt, other);
  // Own host copies (on a host backend a mirror would be the solver's arrays themselves).
  auto copyOf = [](auto v) {
    Kokkos::View<typename decltype(v)::non_const_data_type, Kokkos::HostSpace> h("test::copy", v.extent(0));
    Kokkos::deep_copy(h, v);
    return h;
  };
  fluid.moveMesh(pts);
  fluid.solve();
  const auto U1 = copyOf(fluid.velocity());
  const auto p1 = copyOf(fluid.pressure());
  const auto phi1 = copyOf(fluid.faceFlux());
  fluid.moveMesh(other);  // another coupling iteration, another interface
  fluid.solve();
  fluid.moveMesh(pts);
  fluid.solve();  // continued from the last answer
  double continued = 0;
  {
    const auto U = copyOf(fluid.velocity());
    for (std::size_t c = 0; c < U.extent(0); ++c)
      for (int k = 0; k < 3; ++k) continued = std::max(continued, std::abs(U(c, k) - U1(c, k)));
  }
  EXPECT_GT(continued, 1e-8) << "a solve continued from another answer lands elsewhere";
  fluid.restoreStepStart();
  fluid.solve();
  const auto U2 = copyOf(fluid.velocity());
  const auto p2 = copyOf(fluid.pressure());
  const auto phi2 = copyOf(fluid.faceFlux());
  double dU = 0, dp = 0, dphi = 0;
  for (std::size_t c = 0; c < U2.extent(0); ++c) {
    dp = std::max(dp, std::abs(p2(c) - p1(c)));
    for (int k = 0; k < 3; ++k) dU = std::max(dU, std::abs(U2(c, k) - U1(c, k)));
  }
  for (std::size_t f = 0; f < phi2.extent(0); ++f) dphi = std::max(dphi, std::abs(phi2(f) - phi1(f)));
  std::printf("restored: |dU| %.2e |dp| %.2e |dphi| %.2e; continued |dU| %.2e\n", dU, dp, dphi, continued);
  EXPECT_EQ(dU, 0.0);
  EXPECT_EQ(dp, 0.0);
  EXPECT_EQ(dphi, 0.0);
}
