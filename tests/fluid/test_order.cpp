// Observed orders of accuracy.
//  - Space: Kovasznay flow (exact steady Navier-Stokes solution, Re = 40) on three refinements of
//    a Cartesian mesh and of a smoothly distorted (non-orthogonal) mesh.
//  - Time: 2D Taylor-Green vortex on a fixed mesh, self-convergence in dt (the spatial error cancels):
//    order = log2(|u_dt - u_dt/2| / |u_dt/2 - u_dt/4|); BDF2 must show 2, Euler 1.
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

constexpr double kPi = 3.14159265358979323846;

HexMesh square2d(double x0, double x1, double y0, double y1, int nx, int ny, double distortion) {
  auto spec = boxSpec({x0, y0, 0}, {x1, y1, (x1 - x0) / nx}, {nx, ny, 1});
  spec.blocks[0].patches = {"walls", "walls", "walls", "walls", "frontBack", "frontBack"};
  spec.patchKinds = {{"frontBack", PatchKind::Empty}};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  if (distortion != 0.0) {
    // Smooth interior distortion, the same on front and back (the mesh stays an extrusion).
    auto pts = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.points());
    const double lx = x1 - x0, ly = y1 - y0;
    for (int n = 0; n < mesh.nNodes(); ++n) {
      const double s = (pts(n, 0) - x0) / lx, t = (pts(n, 1) - y0) / ly;
      const double bump = std::sin(kPi * s) * std::sin(kPi * t);
      pts(n, 0) += distortion * lx * bump * std::sin(2 * kPi * t);
      pts(n, 1) += distortion * ly * bump * std::sin(2 * kPi * s);
    }
    Kokkos::deep_copy(mesh.points(), pts);
  }
  return mesh;
}

// --- Kovasznay ----------------------------------------------------------------------------------

constexpr double kRe = 40.0;
double lambdaK() { return kRe / 2 - std::sqrt(kRe * kRe / 4 + 4 * kPi * kPi); }
Vec3 kovasznay(const Vec3& x, real) {
  const double l = lambdaK();
  return {1 - std::exp(l * x[0]) * std::cos(2 * kPi * x[1]),
          l / (2 * kPi) * std::exp(l * x[0]) * std::sin(2 * kPi * x[1]), 0.0};
}

double kovasznayError(int n, double distortion, int* iterations) {
  HexMesh mesh = square2d(-0.5, 1.0, -0.5, 1.5, 3 * n, 4 * n, distortion);
  FluidOptions o;
  o.density = 1;
  o.viscosity = 1.0 / kRe;
  o.timeScheme = TimeScheme::Steady;
  o.pimple.nOuterCorrectors = 3000;
  o.pimple.nCorrectors = 1;
  o.pimple.nNonOrthogonalCorrectors = distortion != 0.0 ? 1 : 0;
  o.pimple.relaxVelocity = 0.9;
  o.pimple.relaxPressure = 0.3;
  o.pimple.outerTolerance = 1e-9;
  o.momentumSolver = {1e-12, 0.01, 500};
  o.pressureSolver = {1e-12, 0.01, 5000};
  o.initialVelocity = {1, 0, 0};
  PatchBC w;
  w.type = BoundaryType::FixedVelocity;
  w.profile = Profile::Function;
  w.velocityFunction = kovasznay;
  o.boundaries["walls"] = w;
  FluidSolver fluid(mesh, o);
  const auto r = fluid.solveStep(0.0, 1.0);
  EXPECT_TRUE(r.ok && r.converged) << "n = " << n;
  *iterations = r.outerIterations;
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  double e = 0;
  for (int c = 0; c < mesh.nCells(); ++c) {
    const auto ex = kovasznay({C(c, 0), C(c, 1), C(c, 2)}, 0);
    e = std::max(e, std::hypot(U(c, 0) - ex[0], U(c, 1) - ex[1]));
  }
  return e;
}

void spatialOrder(double distortion, double minOrder) {
  const int ns[3] = {4, 8, 16};
  double err[3];
  for (int k = 0; k < 3; ++k) {
    int its = 0;
    err[k] = kovasznayError(ns[k], distortion, &its);
    std::printf("kovasznay distortion %.2f h = %.4f: max |u - exact| = %.3e (%d SIMPLE iterations)\n", distortion,
                0.5 / ns[k], err[k], its);
  }
  const double o1 = std::log2(err[0] / err[1]), o2 = std::log2(err[1] / err[2]);
  std::printf("kovasznay distortion %.2f observed order %.3f %.3f\n", distortion, o1, o2);
  EXPECT_GT(o2, minOrder);
  EXPECT_LT(err[2], 0.05);
}

// --- Taylor-Green --------------------------------------------------------------------------------

constexpr double kNuTG = 0.05;
Vec3 taylorGreen(const Vec3& x, real t) {
  const double F = std::exp(-2 * kNuTG * 4 * kPi * kPi * t);
  return {-std::cos(2 * kPi * x[0]) * std::sin(2 * kPi * x[1]) * F,
          std::sin(2 * kPi * x[0]) * std::cos(2 * kPi * x[1]) * F, 0.0};
}

std::vector<double> taylorGreenRun(TimeScheme scheme, int nSteps, double T) {
  HexMesh mesh = square2d(0, 1, 0, 1, 16, 16, 0.0);
  FluidOptions o;
  o.density = 1;
  o.viscosity = kNuTG;
  o.timeScheme = scheme;
  o.pimple.nOuterCorrectors = 30;
  o.pimple.nCorrectors = 2;
  o.pimple.outerTolerance = 1e-10;
  o.momentumSolver = {1e-13, 0, 500};
  o.pressureSolver = {1e-13, 0, 5000};
  PatchBC w;
  w.type = BoundaryType::FixedVelocity;
  w.profile = Profile::Function;
  w.velocityFunction = taylorGreen;
  o.boundaries["walls"] = w;
  FluidSolver fluid(mesh, o);
  {
    auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
    Real3View u0("test::u0", mesh.nCells());
    auto h = Kokkos::create_mirror_view(u0);
    for (int c = 0; c < mesh.nCells(); ++c) {
      const auto v = taylorGreen({C(c, 0), C(c, 1), 0}, 0);
      for (int k = 0; k < 3; ++k) h(c, k) = v[k];
    }
    Kokkos::deep_copy(u0, h);
    fluid.setVelocity(u0);
  }
  const double dt = T / nSteps;
  for (int s = 0; s < nSteps; ++s) {
    const auto r = fluid.solveStep(s * dt, dt);
    EXPECT_TRUE(r.ok);
  }
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  std::vector<double> out;
  for (int c = 0; c < mesh.nCells(); ++c) {
    out.push_back(U(c, 0));
    out.push_back(U(c, 1));
  }
  return out;
}

double maxDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

double temporalOrder(TimeScheme scheme) {
  const double T = 0.2;
  const auto u1 = taylorGreenRun(scheme, 4, T);
  const auto u2 = taylorGreenRun(scheme, 8, T);
  const auto u3 = taylorGreenRun(scheme, 16, T);
  const double d12 = maxDiff(u1, u2), d23 = maxDiff(u2, u3);
  const double order = std::log2(d12 / d23);
  std::printf("taylor-green %s: |u_dt - u_dt/2| = %.3e, |u_dt/2 - u_dt/4| = %.3e, observed order %.3f\n",
              toString(scheme), d12, d23, order);
  return order;
}

}  // namespace

TEST(OrderOfAccuracy, KovasznaySpatialOrderCartesian) { spatialOrder(0.0, 1.8); }

TEST(OrderOfAccuracy, KovasznaySpatialOrderDistortedMesh) { spatialOrder(0.04, 1.8); }

TEST(OrderOfAccuracy, TaylorGreenTemporalOrderBDF2) { EXPECT_GT(temporalOrder(TimeScheme::BDF2), 1.8); }

TEST(OrderOfAccuracy, TaylorGreenTemporalOrderEuler) {
  const double order = temporalOrder(TimeScheme::Euler);
  EXPECT_GT(order, 0.8);
  EXPECT_LT(order, 1.3);
}
