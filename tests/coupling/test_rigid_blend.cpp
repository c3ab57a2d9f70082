// The distance-weighted rigid part of the mesh motion (coupling/motion/RigidBlend, the seed's
// section 3.2), on a box with a square hole (the body) turned about its centre:
//  - the distance is the exact distance to the nearest node of the body, and the weight has its
//    three ranges;
//  - a share w of a turn is the turn by w times the angle: half of a 180-degree turn is a
//    90-degree turn (a blend of positions would put the node on the axis);
//  - nodes within innerDistance move exactly rigidly, nodes beyond outerDistance not at all;
//  - turned by 45 degrees, the Laplacian alone inverts cells at the hole's corners; with the rigid
//    blend under it every cell stays valid (minimum scaled Jacobian 0.52).
#include "coupling/motion/MeshSmoother.hpp"
#include "coupling/motion/RigidBlend.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/MeshGeometry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using mfsi::lid_t;
using mfsi::coupling::MeshSmoother;
using mfsi::coupling::MeshSmootherOptions;
using mfsi::coupling::RigidBlend;

namespace {

/// [-2, 2]^2 x [0, 0.1] with the hole [-0.5, 0.5]^2 (patch "body"), one cell thick (frontBack
/// empty), the outer sides "outer"; n cells across the hole's side, m across each outer strip.
mfsi::HexMesh boxWithHole(int n, int m, double half = 2) {
  mfsi::BlockMeshSpec spec;
  const double edge[4] = {-half, -0.5, 0.5, half};
  const int cells[3] = {m, n, m};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (i == 1 && j == 1) continue;
      mfsi::BlockSpec b;
      b.min = {edge[i], edge[j], 0};
      b.max = {edge[i + 1], edge[j + 1], 0.1};
      b.cells = {cells[i], cells[j], 1};
      b.patches = {i == 0 ? "outer" : (i == 2 && j == 1 ? "body" : ""),
                   i == 2 ? "outer" : (i == 0 && j == 1 ? "body" : ""),
                   j == 0 ? "outer" : (j == 2 && i == 1 ? "body" : ""),
                   j == 2 ? "outer" : (j == 0 && i == 1 ? "body" : ""),
                   "frontBack",
                   "frontBack"};
      spec.blocks.push_back(b);
    }
  spec.patchKinds = {{"frontBack", mfsi::PatchKind::Empty}, {"body", mfsi::PatchKind::Wall},
                     {"outer", mfsi::PatchKind::Wall}};
  return mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
}

std::vector<lid_t> patchNodes(const mfsi::HexMesh& mesh, const std::string& name) {
  const int pi = mesh.findPatch(name);
  EXPECT_GE(pi, 0) << name;
  auto fn = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceNodes());
  std::vector<char> on(static_cast<std::size_t>(mesh.nNodes()), 0);
  const auto& p = mesh.patches()[pi];
  for (lid_t f = p.start; f < p.start + p.size; ++f)
    for (int a = 0; a < 4; ++a) on[fn(f, a)] = 1;
  std::vector<lid_t> out;
  for (lid_t v = 0; v < mesh.nNodes(); ++v)
    if (on[v]) out.push_back(v);
  return out;
}

std::vector<std::array<mfsi::real, 3>> patchPoints(const mfsi::HexMesh& mesh, const std::string& name) {
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  std::vector<std::array<mfsi::real, 3>> out;
  for (lid_t v : patchNodes(mesh, name)) out.push_back({X(v, 0), X(v, 1), X(v, 2)});
  return out;
}

/// z-rotation of (x, y) by angle a.
std::array<double, 2> turned(double x, double y, double a) {
  return {std::cos(a) * x - std::sin(a) * y, std::sin(a) * x + std::cos(a) * y};
}

}  // namespace

TEST(RigidBlend, DistanceAndWeight) {
  EXPECT_EQ(RigidBlend::weight(0.1, 0.2, 1.0), 1.0);
  EXPECT_EQ(RigidBlend::weight(1.5, 0.2, 1.0), 0.0);
  EXPECT_NEAR(RigidBlend::weight(0.6, 0.2, 1.0), 0.5, 1e-15);
  EXPECT_NEAR(RigidBlend::weight(0.4, 0.2, 1.0), 0.5 * (1 + std::cos(M_PI / 4)), 1e-15);
  // Distance to the hole's nodes (the region outside a convex body): the nearest node's, exactly.
  const auto mesh = boxWithHole(4, 6);
  const std::vector<lid_t> body = patchNodes(mesh, "body");
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  const auto d = RigidBlend::nearestDistance(mesh, patchPoints(mesh, "body"));
  for (lid_t v = 0; v < mesh.nNodes(); ++v) {
    double exact = 1e300;
    for (lid_t s : body)
      exact = std::min(exact, std::sqrt(std::pow(X(v, 0) - X(s, 0), 2) + std::pow(X(v, 1) - X(s, 1), 2) +
                                        std::pow(X(v, 2) - X(s, 2), 2)));
    ASSERT_NEAR(d[v], exact, 1e-12) << "node " << v;
  }
}

TEST(RigidBlend, AShareOfATurnIsTheTurnByThatShareOfTheAngle) {
  const auto mesh = boxWithHole(4, 6);
  const double inner = 0.25, outer = 0.75;
  const RigidBlend blend({{patchPoints(mesh, "body"), inner, outer}}, mesh);
  const auto d = RigidBlend::nearestDistance(mesh, patchPoints(mesh, "body"));
  mfsi::ExecSpace exec;
  mfsi::Real3View base("base", mesh.nNodes());
  const double angle = M_PI;
  auto T = mfsi::RigidPlacement::rotationAbout({0, 0, 1}, angle, {0, 0, 0.05});
  T.placed = {0.1, -0.2, 0.05};  // and the centre moved
  blend.displacement(exec, {T}, base);
  exec.fence();
  auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), base);
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  int rigid = 0, still = 0, between = 0;
  for (lid_t v = 0; v < mesh.nNodes(); ++v) {
    const double w = blend.weight(v, 0);
    ASSERT_NEAR(w, RigidBlend::weight(d[v], inner, outer), 1e-15);
    const auto r = turned(X(v, 0), X(v, 1), w * angle);
    const double ex = r[0] + w * 0.1 - X(v, 0), ey = r[1] - w * 0.2 - X(v, 1);
    ASSERT_NEAR(hb(v, 0), ex, 1e-13) << "node " << v << " w " << w;
    ASSERT_NEAR(hb(v, 1), ey, 1e-13) << "node " << v << " w " << w;
    ASSERT_NEAR(hb(v, 2), 0, 1e-13);
    if (w == 1) ++rigid;
    if (w == 0) {
      ++still;
      ASSERT_EQ(hb(v, 0), 0.0);
    }
    if (std::abs(w - 0.5) < 1e-12) {
      // Half of the 180-degree turn: the node keeps its distance from the axis.
      ++between;
      const double x = X(v, 0) + hb(v, 0) - 0.05, y = X(v, 1) + hb(v, 1) + 0.1;
      EXPECT_NEAR(std::hypot(x, y), std::hypot(X(v, 0), X(v, 1)), 1e-12);
    }
  }
  EXPECT_GT(rigid, 0);
  EXPECT_GT(still, 0);
  EXPECT_GT(between, 0) << "nodes at d = 0.5, the weight's midpoint";
}

TEST(RigidBlend, ATurnedBodyKeepsTheCellsNextToItValid) {
  const auto run = [](bool blended, double degrees) {
    auto mesh = boxWithHole(8, 20, 3);
    MeshSmootherOptions o;
    o.method = mfsi::coupling::MeshMotionMethod::ConjugateGradient;
    o.relTol = 1e-8;
    MeshSmoother s(mesh, o);
    const std::vector<lid_t> body = patchNodes(mesh, "body");
    const RigidBlend blend({{patchPoints(mesh, "body"), 0.15, 2.4}}, mesh);
    mfsi::ExecSpace exec;
    mfsi::Real3View base("base", mesh.nNodes());
    const double a = degrees * M_PI / 180;
    const auto T = mfsi::RigidPlacement::rotationAbout({0, 0, 1}, a, {0, 0, 0.05});
    if (blended) {
      blend.displacement(exec, {T}, base);
      s.setBase(base);
    }
    auto hd = Kokkos::create_mirror_view(s.displacement());
    auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
    Kokkos::deep_copy(hd, 0.0);
    for (lid_t v : body) {
      const auto r = turned(X(v, 0), X(v, 1), a);
      hd(v, 0) = r[0] - X(v, 0);
      hd(v, 1) = r[1] - X(v, 1);
    }
    Kokkos::deep_copy(s.displacement(), hd);
    double q = 0;
    try {
      q = s.move(exec).minScaledJacobian;
    } catch (const mfsi::DivergenceError&) {
      q = -1;  // refused: a cell inverts
    }
    exec.fence();
    if (blended) {
      // The prescribed nodes are where they were put, and nodes within innerDistance turn rigidly.
      auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
      for (lid_t v = 0; v < mesh.nNodes(); ++v) {
        if (blend.weight(v, 0) < 1) continue;
        const auto r = turned(X(v, 0), X(v, 1), a);
        EXPECT_NEAR(x(v, 0), r[0], 1e-12) << "node " << v;
        EXPECT_NEAR(x(v, 1), r[1], 1e-12) << "node " << v;
      }
    }
    return q;
  };
  for (double deg : {30, 60, 90})
    std::printf("%g-degree turn: minimum scaled Jacobian %.4f alone, %.4f blended (-1: refused)\n", deg,
                run(false, deg), run(true, deg));
  const double plain = run(false, 45), blended = run(true, 45);
  std::printf("45-degree turn: minimum scaled Jacobian %.4f with the Laplacian alone, %.4f with the rigid blend\n",
              plain, blended);
  EXPECT_GT(blended, 0.45);
  EXPECT_LT(plain, 0.0) << "the Laplacian alone inverts a cell at the hole's corners";
  // No turn: the blend adds exactly nothing.
  EXPECT_NEAR(run(true, 0), 1.0, 1e-12);
}
