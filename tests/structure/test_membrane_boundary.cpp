// Loads and boundary features of the membrane solver, each checked against an exact statement:
//  - uniform pressure, per-node and per-element fields, a time function and the ramped,
//    insidePoint-signed pressure offset give the same residual when they describe the same load;
//  - lumped and consistent pressure have the same resultant;
//  - constrainToNormal nodes move along their normal only, and anchor springs carry the whole
//    dead pressure load (global equilibrium);
//  - edge beams in a stretched strip add EA E_GL (1 + e) each to the end reaction; tension-only
//    beams carry nothing in compression;
//  - corner springs balance distributed nodal forces.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <cmath>
#include <random>

using namespace mfsi;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

std::vector<double> hostCopy(const RealView& v) {
  auto h = Kokkos::create_mirror(v);
  Kokkos::deep_copy(h, v);
  return std::vector<double>(h.data(), h.data() + h.extent(0));
}

MembraneMesh smallDisc() {
  MembraneDiscSpec d;
  d.nCore = 4;
  d.nRing = 3;
  return buildMembraneMesh(generateDiscMesh(d));
}

MembraneOptions material() {
  MembraneOptions opt;
  opt.material = {1e6, 0.3, 1e-3, 500, 5.0};
  return opt;
}

/// Residual of a randomly deformed disc under the given loads at time t.
std::vector<double> residualWith(const MembraneMesh& mesh, const MembraneLoads& loads, double t) {
  MembraneSolver s(mesh, material(), {}, loads);
  auto u = Kokkos::create_mirror(s.displacement());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uni(-0.02, 0.02);
  for (std::size_t i = 0; i < u.extent(0); ++i) u(i) = uni(rng);
  Kokkos::deep_copy(s.displacement(), u);
  return hostCopy(s.residual(t));
}

void expectSame(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) {
  double scale = 0;
  for (double v : a) scale = std::max(scale, std::abs(v));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_TRUE(near(a[i], b[i], Tol{1e-12 * scale, 0}, what + " dof " + std::to_string(i)));
}

}  // namespace

TEST(MembraneLoads, PressureDescriptionsAgree) {
  const MembraneMesh mesh = smallDisc();
  const double p = 300;
  MembraneLoads uniform;
  uniform.pressure = p;
  const auto ref = residualWith(mesh, uniform, 0);

  MembraneLoads nodal;
  nodal.nodePressure = RealView("p", mesh.nNodes());
  Kokkos::deep_copy(nodal.nodePressure, p);
  expectSame(ref, residualWith(mesh, nodal, 0), "node field");

  MembraneLoads element;
  element.elementPressure = RealView("pe", mesh.nElements());
  Kokkos::deep_copy(element.elementPressure, p);
  expectSame(ref, residualWith(mesh, element, 0), "element field");

  MembraneLoads timed;
  timed.pressure = p / 3;
  timed.pressureTime = [](real t) { return 2 * t; };
  expectSame(ref, residualWith(mesh, timed, 1.5), "time function");

  // Offset 2p ramped over 2 s, evaluated at t = 1: +p where normals point away from insidePoint.
  MembraneLoads offset;
  offset.pressureOffset = 2 * p;
  offset.pressureOffsetRampTime = 2.0;
  offset.insidePoint = {0, 0, -1};
  expectSame(ref, residualWith(mesh, offset, 1.0), "offset below");
  MembraneLoads minus;
  minus.pressure = -p;
  offset.insidePoint = {0, 0, 1};
  expectSame(residualWith(mesh, minus, 0), residualWith(mesh, offset, 1.0), "offset above");
}

TEST(MembraneLoads, LumpedAndConsistentPressureHaveTheSameResultant) {
  const MembraneMesh mesh = smallDisc();
  MembraneLoads c, l;
  c.pressure = l.pressure = 300;
  l.integration = MembranePressureIntegration::Lumped;
  const auto rc = residualWith(mesh, c, 0), rl = residualWith(mesh, l, 0);
  double diff = 0, sum[3] = {0, 0, 0}, total = 0;
  for (std::size_t i = 0; i < rc.size(); ++i) {
    diff = std::max(diff, std::abs(rc[i] - rl[i]));
    sum[i % 3] += rc[i] - rl[i];
    total += std::abs(rc[i]);
  }
  EXPECT_GT(diff, 1e-6 * total) << "the two distributions should differ node by node";
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(sum[k], 0, Tol{1e-12 * total, 0}, "resultant difference"));
}

TEST(MembraneBoundary, NormalConstraintAndAnchorSpringsCarryTheLoad) {
  MembraneRectangleSpec rect;
  rect.nx = rect.ny = 6;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));
  MembraneBoundary bc;
  bc.normalNodes = mesh.boundaryNodes();
  const double k = 2e3;
  bc.edgeSprings = makeAnchorSprings(mesh, mesh.boundaryNodes(), k);
  MembraneLoads loads;
  loads.pressure = 50;
  loads.direction = MembranePressureDirection::Dead;
  MembraneOptions opt = material();
  opt.tolerance = 1e-10;
  MembraneSolver s(mesh, opt, bc, loads);
  const auto rep = s.solveStatic();
  ASSERT_TRUE(rep.converged);
  const auto u = hostCopy(s.displacement());
  double springForce = 0;
  for (lid_t n : mesh.boundaryNodes()) {
    EXPECT_EQ(u[3 * n], 0.0);
    EXPECT_EQ(u[3 * n + 1], 0.0);
    springForce += k * u[3 * n + 2];
  }
  EXPECT_GT(s.summary().at("centreDeflection"), u[3 * mesh.boundaryNodes().front() + 2]);
  EXPECT_TRUE(near(springForce, loads.pressure * mesh.referenceArea(), Tol{0, 1e-8}, "springs carry p A"));
}

namespace {

/// Strip [0, 2] x [0, 0.5] (nu = 0), x = 0 clamped, x = 2 pulled by delta; beams along y = 0 and
/// y = 0.5. Returns the x reaction at the pulled end.
double stripReaction(double delta, double EA, bool tensionOnly, MembraneSolveReport& rep) {
  MembraneRectangleSpec rect;
  rect.lx = 2;
  rect.ly = 0.5;
  rect.nx = 8;
  rect.ny = 2;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("xmin"), {}, {}});
  MembraneClamp pulled;
  pulled.nodes = mesh.nodeSet("xmax");
  pulled.offsets.assign(pulled.nodes.size(), {delta, 0, 0});
  bc.clamps.push_back(pulled);
  for (const char* side : {"ymin", "ymax"}) {
    const auto beams = makeEdgeBeams(mesh.nodeSet(side), EA, false, tensionOnly);
    bc.edgeBeams.insert(bc.edgeBeams.end(), beams.begin(), beams.end());
  }
  MembraneOptions opt;
  opt.material = {1e6, 0.0, 1e-3, 0, 0};
  opt.tolerance = 1e-11;
  MembraneSolver s(mesh, opt, bc);
  rep = s.solveStatic();
  const auto R = hostCopy(s.residual(0));
  double reaction = 0;
  for (lid_t n : mesh.nodeSet("xmax")) reaction -= R[3 * n];
  return reaction;
}

}  // namespace

TEST(MembraneBoundary, EdgeBeamsAddTheirAxialForce) {
  const double E = 1e6, h = 1e-3, W = 0.5, EA = 200.0;
  for (double delta : {0.1, -0.05}) {
    const double e = delta / 2, Egl = 0.5 * ((1 + e) * (1 + e) - 1);
    for (bool tensionOnly : {false, true}) {
      MembraneSolveReport rep;
      const double reaction = stripReaction(delta, EA, tensionOnly, rep);
      ASSERT_TRUE(rep.converged);
      const double beams = (tensionOnly && delta < 0) ? 0 : 2 * EA;
      EXPECT_TRUE(near(reaction, (E * h * W + beams) * Egl * (1 + e), Tol{0, 1e-8}, "end reaction"));
    }
  }
}

TEST(MembraneBoundary, CornerSpringsBalanceNodalForces) {
  MembraneRectangleSpec rect;
  rect.nx = rect.ny = 4;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));
  MembraneBoundary bc;
  const double k = 5e3;
  bc.cornerSprings = makeAnchorSprings(mesh, mesh.nodeSet("corners"), k);
  MembraneLoads loads;
  loads.nodeForce = Real3View("f", mesh.nNodes());
  auto f = Kokkos::create_mirror_view(loads.nodeForce);
  for (lid_t n = 0; n < mesh.nNodes(); ++n) {
    f(n, 0) = 0.3;
    f(n, 1) = -0.1 * mesh.hostPoints()[n][0];
    f(n, 2) = 0;
  }
  Kokkos::deep_copy(loads.nodeForce, f);
  MembraneOptions opt = material();
  opt.material.preStress = 0;
  opt.tolerance = 1e-10;
  MembraneSolver s(mesh, opt, bc, loads);
  ASSERT_TRUE(s.solveStatic().converged);
  const auto u = hostCopy(s.displacement());
  double fs[2] = {0, 0}, ft[2] = {0, 0};
  for (lid_t c : mesh.nodeSet("corners"))
    for (int d = 0; d < 2; ++d) fs[d] += k * u[3 * c + d];
  for (lid_t n = 0; n < mesh.nNodes(); ++n)
    for (int d = 0; d < 2; ++d) ft[d] += f(n, d);
  for (int d = 0; d < 2; ++d) EXPECT_TRUE(near(fs[d], ft[d], Tol{1e-9, 1e-8}, "spring reaction = applied force"));
}
