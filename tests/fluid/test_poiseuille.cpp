// Plane Poiseuille flow in a 2D channel (one cell thick, empty front/back): the parabolic profile and
// the linear pressure drop are reproduced with second-order accuracy; flow-rate inlets and
// resistance outlets impose exactly what they promise.
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/Loads.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <cstdlib>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kH = 1.0, kL = 2.0, kMu = 0.1, kUmean = 1.0;

HexMesh channel(int ny, double thickness) {
  auto spec = boxSpec({0, 0, 0}, {kL, kH, thickness}, {2 * ny, ny, 1});
  spec.blocks[0].patches = {"inlet", "outlet", "bottom", "top", "frontBack", "frontBack"};
  spec.patchKinds = {{"bottom", PatchKind::Wall}, {"top", PatchKind::Wall}, {"frontBack", PatchKind::Empty}};
  return buildHexMesh(generateBlockMesh(spec));
}

FluidOptions steadyOptions() {
  FluidOptions o;
  o.density = 1.0;
  o.viscosity = kMu;
  o.timeScheme = TimeScheme::Steady;
  o.pimple.nOuterCorrectors = 4000;
  o.pimple.nCorrectors = 1;
  o.pimple.relaxVelocity = 0.9;
  o.pimple.relaxPressure = 0.3;
  o.pimple.outerTolerance = 1e-9;
  o.momentumSolver = {1e-12, 0.01, 500};
  o.pressureSolver = {1e-12, 0.01, 5000};
  PatchBC out;
  out.type = BoundaryType::FixedPressure;
  out.pressure = 0.0;
  o.boundaries["outlet"] = out;
  return o;
}

double exactU(double y) { return 6.0 * kUmean * y * (kH - y) / (kH * kH); }

struct ChannelErrors {
  double maxErrU = 0, maxV = 0, dpdx = 0;
  bool converged = false;
};

ChannelErrors solveChannel(int ny, const PatchBC& inlet) {
  HexMesh mesh = channel(ny, kH / ny);
  FluidOptions o = steadyOptions();
  o.boundaries["inlet"] = inlet;
  FluidSolver fluid(mesh, o);
  const auto r = fluid.solveStep(0.0, 1.0);
  ChannelErrors e;
  e.converged = r.ok && r.converged;
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  // Pressure gradient from a least-squares line through the cells of the middle half.
  double sx = 0, sp = 0, sxx = 0, sxp = 0;
  int n = 0;
  for (int c = 0; c < mesh.nCells(); ++c) {
    e.maxErrU = std::max(e.maxErrU, std::abs(U(c, 0) - exactU(C(c, 1))));
    e.maxV = std::max(e.maxV, std::abs(U(c, 1)));
    if (C(c, 0) > 0.5 && C(c, 0) < 1.5) {
      sx += C(c, 0);
      sp += p(c);
      sxx += C(c, 0) * C(c, 0);
      sxp += C(c, 0) * p(c);
      ++n;
    }
  }
  e.dpdx = (n * sxp - sx * sp) / (n * sxx - sx * sx);
  return e;
}

PatchBC parabolicInlet() {
  PatchBC in;
  in.type = BoundaryType::FixedVelocity;
  in.velocity = {1.5 * kUmean, 0, 0};
  in.profile = Profile::Parabolic;
  in.parabolicAxes = {false, true, false};
  return in;
}

}  // namespace

// The 1D cell-centred solution of mu u'' = dp/dx between walls (half-cell wall distance), scaled to
// carry the flow rate q per unit depth: the gold the 2D solver must reproduce away from the inlet.
std::vector<double> discreteFullyDeveloped(int ny, double q) {
  const double h = kH / ny;
  std::vector<double> a(ny, 1.0), b(ny, -2.0), c(ny, 1.0), d(ny, h * h);
  b[0] = b[ny - 1] = -3.0;  // wall neighbour at h/2: 2 (0 - u) / h
  for (int j = 1; j < ny; ++j) {  // Thomas algorithm
    const double m = a[j] / b[j - 1];
    b[j] -= m * c[j - 1];
    d[j] -= m * d[j - 1];
  }
  std::vector<double> u(ny);
  u[ny - 1] = d[ny - 1] / b[ny - 1];
  for (int j = ny - 2; j >= 0; --j) u[j] = (d[j] - c[j] * u[j + 1]) / b[j];
  double sum = 0;
  for (double v : u) sum += v * h;
  for (double& v : u) v *= q / sum;
  return u;
}

TEST(Poiseuille, ReproducesTheDiscreteFullyDevelopedProfile) {
  const int ny = 16;
  HexMesh mesh = channel(ny, kH / ny);
  FluidOptions o = steadyOptions();
  o.boundaries["inlet"] = parabolicInlet();
  FluidSolver fluid(mesh, o);
  const auto r = fluid.solveStep(0.0, 1.0);
  ASSERT_TRUE(r.ok && r.converged);
  // Flow rate per unit depth actually imposed: the midpoint sum of the inlet parabola.
  const double h = kH / ny;
  double q = 0;
  for (int j = 0; j < ny; ++j) q += exactU((j + 0.5) * h) * h;
  const auto gold = discreteFullyDeveloped(ny, q);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  int checked = 0;
  for (int c = 0; c < mesh.nCells(); ++c) {
    // The inlet's O(h^2) mismatch with the discrete profile decays like exp(-7x): gone by x = 1.5.
    if (C(c, 0) < 1.5) continue;
    const int j = static_cast<int>(C(c, 1) / h);
    ASSERT_TRUE(near(U(c, 0), gold[j], Tol{1e-6, 0}, "u in cell " + std::to_string(c)));
    ASSERT_TRUE(near(U(c, 1), 0.0, Tol{1e-6, 0}, "v in cell " + std::to_string(c)));
    ++checked;
  }
  EXPECT_EQ(checked, ny * ny / 2);
}

TEST(Poiseuille, ParabolicProfileConvergesAtSecondOrder) {
  // Flow-rate inlet with the exact flow rate, so the only error is the discretisation's.
  const int ns[3] = {8, 16, 32};
  double err[3];
  for (int k = 0; k < 3; ++k) {
    PatchBC in;
    in.type = BoundaryType::FlowRate;
    in.flowRate = kUmean * kH * (kH / ns[k]);
    in.profile = Profile::Parabolic;
    in.parabolicAxes = {false, true, false};
    const auto e = solveChannel(ns[k], in);
    ASSERT_TRUE(e.converged) << "ny = " << ns[k];
    err[k] = e.maxErrU;
    std::printf("poiseuille ny=%d: max|u - exact| = %.3e, max|v| = %.3e, dp/dx = %.6f (exact %.6f)\n", ns[k],
                e.maxErrU, e.maxV, e.dpdx, -12.0 * kMu * kUmean / (kH * kH));
    EXPECT_TRUE(near(e.dpdx, -12.0 * kMu * kUmean / (kH * kH), Tol{0, 0.04}, "dp/dx"));
  }
  const double order1 = std::log2(err[0] / err[1]), order2 = std::log2(err[1] / err[2]);
  std::printf("poiseuille observed order %.3f %.3f\n", order1, order2);
  EXPECT_GT(order1, 1.8);
  EXPECT_GT(order2, 1.8);
}

TEST(Poiseuille, FlowRateInletImposesTheDiscreteFlowRate) {
  const int ny = 8;
  HexMesh mesh = channel(ny, 0.1);
  FluidOptions o = steadyOptions();
  o.pimple.nOuterCorrectors = 50;
  PatchBC in;
  in.type = BoundaryType::FlowRate;
  in.flowRate = 0.25;
  in.profile = Profile::Parabolic;
  in.parabolicAxes = {false, true, false};
  in.timeFunction.kind = TimeFunction::Kind::CosineRamp;
  in.timeFunction.period = 2.0;
  o.boundaries["inlet"] = in;
  FluidSolver fluid(mesh, o);
  fluid.solveStep(0.0, 0.5);  // BCs at t = 0.5: ramp (1 - cos(pi/4)) / 2
  const double q = 0.25 * 0.5 * (1.0 - std::cos(3.14159265358979323846 * 0.5 / 2.0));
  auto phi = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceFlux());
  const auto& pi = mesh.patches()[mesh.patchIndex("inlet")];
  const auto& po = mesh.patches()[mesh.patchIndex("outlet")];
  double qin = 0, qout = 0;
  for (int f = pi.start; f < pi.start + pi.size; ++f) qin -= phi(f);
  for (int f = po.start; f < po.start + po.size; ++f) qout += phi(f);
  EXPECT_TRUE(near(qin, q, Tol{0, 1e-13}, "inflow"));
  EXPECT_TRUE(near(qout, q, Tol{0, 1e-6}, "outflow (continuity)"));
}

TEST(Poiseuille, ResistanceOutletSetsPressureFromFlowRate) {
  const int ny = 6;
  HexMesh mesh = channel(ny, kH / ny);
  FluidOptions o = steadyOptions();
  o.pimple.outerTolerance = 1e-8;
  o.boundaries["inlet"] = parabolicInlet();
  PatchBC out;
  out.type = BoundaryType::Resistance;
  out.resistance = 3.0;
  out.pressure = 0.5;
  o.boundaries["outlet"] = out;
  FluidSolver fluid(mesh, o);
  const auto r = fluid.solveStep(0.0, 1.0);
  ASSERT_TRUE(r.ok && r.converged);
  // The imposed flow rate: midpoint sum of the inlet parabola over the faces, times the thickness.
  double q = 0;
  for (int j = 0; j < ny; ++j) q += exactU((j + 0.5) * kH / ny) * (kH / ny) * (kH / ny);
  auto pb = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.boundaryPressure());
  const auto& po = mesh.patches()[mesh.patchIndex("outlet")];
  for (int f = po.start; f < po.start + po.size; ++f)
    ASSERT_TRUE(near(pb(f - mesh.nInternalFaces()), 3.0 * q + 0.5, Tol{0, 1e-4}, "outlet pressure"));
}

TEST(Poiseuille, WallShearStressAndPressureDropLoads) {
  // Force on the bottom wall: shear tau_w = mu dU/dy at y = 0 = 6 mu Umean / H per unit area, along +x.
  const int ny = 16;
  const double dz = kH / ny;
  HexMesh mesh = channel(ny, dz);
  FluidOptions o = steadyOptions();
  o.boundaries["inlet"] = parabolicInlet();
  FluidSolver fluid(mesh, o);
  ASSERT_TRUE(fluid.solveStep(0.0, 1.0).converged);
  const auto bottom = patchLoads(fluid, "bottom", {0, 0, 0});
  const double tauW = 6.0 * kMu * kUmean / kH;
  EXPECT_TRUE(near(bottom.area, kL * dz, Tol{0, 1e-12}, "bottom area"));
  EXPECT_TRUE(near(bottom.viscousForce[0], tauW * kL * dz, Tol{0, 0.03}, "wall shear force"));
  EXPECT_TRUE(near(bottom.viscousForce[1], 0.0, Tol{1e-3 * tauW * kL * dz, 0}, "wall normal viscous force"));
  // Pressure pushes the bottom wall down (-y) with the mean wall pressure times the area.
  EXPECT_LT(bottom.pressureForce[1], 0.0);
  // Global balance: inlet + outlet pressure forces balance the wall shear on both walls (x).
  const auto inlet = patchLoads(fluid, "inlet");
  const auto outlet = patchLoads(fluid, "outlet");
  const auto top = patchLoads(fluid, "top");
  const double fx = inlet.pressureForce[0] + outlet.pressureForce[0];
  EXPECT_TRUE(near(-fx, bottom.viscousForce[0] + top.viscousForce[0], Tol{0, 0.05}, "momentum balance"));
}
