// Membranes mounted on moving bodies (coupling/motion/ParentFrames): node positions, nodal forces
// rotated into the frames, and the nodal forces' share on each body, against hand-derived values
// for a frame turned by 90 degrees about z and for a node blended between two bodies.
#include "coupling/motion/ParentFrames.hpp"

#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

using mfsi::real;
using mfsi::test::near;
using mfsi::test::Tol;
namespace cpl = mfsi::coupling;

namespace {

constexpr double kPi = 3.14159265358979323846;

mfsi::Real3View points(const std::vector<std::array<real, 3>>& p) {
  mfsi::Real3View v("test::points", p.size());
  auto h = Kokkos::create_mirror_view(v);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) h(i, k) = p[i][k];
  Kokkos::deep_copy(v, h);
  return v;
}

}  // namespace

// One body turned by 90 degrees about z through (1, 0, 0), then moved by (0, 0, 2): a node at X
// with relative displacement u sits at Q (X + u - c0) + c; a global force f is Q^T f in the frame;
// the body takes every node's force and its moment about a point.
TEST(ParentFrames, OneTurnedFrameMovesRotatesAndLoads) {
  const std::vector<std::array<real, 3>> nodes = {{1, 0, 0}, {2, 0, 0}, {2, 1, 0}};
  cpl::ParentFrames pf(nodes, {{1, 0, 0}}, {0}, 1);
  mfsi::RigidPlacement T = mfsi::RigidPlacement::rotationAbout({0, 0, 1}, kPi / 2, {1, 0, 0});
  T.placed = {1, 0, 2};
  pf.setTransforms({T});
  const mfsi::ExecSpace exec;
  const auto X = points(nodes);
  mfsi::RealView u("test::u", 9);
  auto hu = Kokkos::create_mirror_view(u);
  for (int k = 0; k < 9; ++k) hu(k) = 0;
  hu(3 * 1 + 1) = 0.5;  // node 1 displaced by (0, 0.5, 0) in the frame
  Kokkos::deep_copy(u, hu);
  mfsi::Real3View x("test::x", 3);
  pf.positions(exec, X, u, x);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  // Q = Rz(90): (a, b, c) -> (-b, a, c). Node 0 at the pivot; node 1: X + u - c0 = (1, 0.5, 0) ->
  // (-0.5, 1, 0) + (1, 0, 2); node 2: (1, 1, 0) -> (-1, 1, 0) + (1, 0, 2).
  const double expect[3][3] = {{1, 0, 2}, {0.5, 1, 2}, {0, 1, 2}};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(hx(i, k), expect[i][k], Tol{1e-14, 0}, "x"));

  const auto f = points({{1, 0, 0}, {0, 2, 0}, {0, 0, 3}});
  mfsi::Real3View fr("test::frameForce", 3);
  pf.toFrames(exec, f, fr);
  auto hf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), fr);
  // Q^T (a, b, c) = (b, -a, c).
  const double frame[3][3] = {{0, -1, 0}, {2, 0, 0}, {0, 0, 3}};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(hf(i, k), frame[i][k], Tol{1e-14, 0}, "Q^T f"));

  const std::array<double, 6> L = pf.nodeLoad(exec, 0, {0, 0, 0}, x, f);
  // Sum of forces (1, 2, 3); moments x_i x f_i: (1,0,2)x(1,0,0) = (0, 2, 0); (0.5,1,2)x(0,2,0) =
  // (-4, 0, 1); (0,1,2)x(0,0,3) = (3, 0, 0).
  const double expectL[6] = {1, 2, 3, -1, 2, 1};
  for (int k = 0; k < 6; ++k) EXPECT_TRUE(near(L[k], expectL[k], Tol{1e-14, 0}, "load"));
}

// Two bodies, the middle node between them with weights 1/2 each: its position blends the two
// motions, its force reaches each body by half and is rotated into the blend of both frames.
TEST(ParentFrames, ABlendedNodeSharesItsForce) {
  const std::vector<std::array<real, 3>> nodes = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  cpl::ParentFrames pf(nodes, {{0, 0, 0}, {2, 0, 0}}, {0, 1}, 2);
  EXPECT_DOUBLE_EQ(pf.weight(1, 0), 0.5);
  EXPECT_DOUBLE_EQ(pf.weight(0, 0), 1.0);
  mfsi::RigidPlacement still;  // body 0 stays
  mfsi::RigidPlacement turned = mfsi::RigidPlacement::rotationAbout({0, 0, 1}, kPi, {2, 0, 0});  // body 1 half-turns
  pf.setTransforms({still, turned});
  const mfsi::ExecSpace exec;
  const auto X = points(nodes);
  mfsi::RealView u("test::u", 9);
  mfsi::Real3View x("test::x", 3);
  pf.positions(exec, X, u, x);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  // Node 1: body 0 keeps it at (1, 0, 0), body 1 turns it to (3, 0, 0): the blend is (2, 0, 0).
  EXPECT_TRUE(near(hx(1, 0), 2.0, Tol{1e-14, 0}, "blend x"));
  const auto f = points({{0, 0, 0}, {0, 4, 0}, {0, 0, 0}});
  const auto L0 = pf.nodeLoad(exec, 0, {0, 0, 0}, x, f);
  const auto L1 = pf.nodeLoad(exec, 1, {0, 0, 0}, x, f);
  EXPECT_TRUE(near(L0[1], 2.0, Tol{1e-14, 0}, "body 0 share"));
  EXPECT_TRUE(near(L1[1], 2.0, Tol{1e-14, 0}, "body 1 share"));
  EXPECT_TRUE(near(L0[5] + L1[5], 8.0, Tol{1e-14, 0}, "moment about z: x 2 * f 4"));
  mfsi::Real3View fr("test::frameForce", 3);
  pf.toFrames(exec, f, fr);
  auto hf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), fr);
  // 1/2 (I + Rz(180))^T (0, 4, 0) = 1/2 ((0, 4, 0) + (0, -4, 0)) = 0.
  EXPECT_TRUE(near(hf(1, 1), 0.0, Tol{1e-14, 0}, "blended frame force"));
}

// The inertial force a frame's motion puts on a node of mass 2 at x = (1, 0, 0), the frame turned by
// 90 degrees about z (centre of mass at the origin), a = (1, 2, 3), omega = (0, 0, 2),
// alpha = (0, 0, 0.5): -m (a + alpha x r + omega x (omega x r) + 2 omega x Q v). At rest in the frame:
// alpha x r = (0, 0.5, 0), omega x (omega x r) = (-4, 0, 0), so f = -2 (-3, 2.5, 3). Moving at
// v = (1, 0, 0) in frame axes, Q v = (0, 1, 0) and the Coriolis term 2 omega x Q v = (-4, 0, 0) adds
// 8 to f_x.
namespace {
/// One node at (1, 0, 0) on a frame turned by 90 degrees about z (centre of mass at the origin),
/// accelerating: a = (1, 2, 3), omega = (0, 0, 2), alpha = (0, 0, 0.5).
cpl::ParentFrames acceleratingTurnedFrame() {
  cpl::ParentFrames pf({{1, 0, 0}}, {{0, 0, 0}}, {0}, 1);
  pf.setTransforms({mfsi::RigidPlacement::rotationAbout({0, 0, 1}, kPi / 2, {0, 0, 0})});
  EXPECT_FALSE(pf.hasAccelerations());
  cpl::ParentFrames::BodyAcceleration acc;
  acc.acceleration = {1, 2, 3};
  acc.omega = {0, 0, 2};
  acc.alpha = {0, 0, 0.5};
  pf.setAccelerations({acc});
  EXPECT_TRUE(pf.hasAccelerations());
  return pf;
}
}  // namespace

TEST(ParentFrames, InertialForceWithCoriolis) {
  const cpl::ParentFrames pf = acceleratingTurnedFrame();
  const mfsi::ExecSpace exec;
  const auto x = points({{1, 0, 0}});
  mfsi::RealView mass("test::mass", 1), v("test::v", 3);
  Kokkos::deep_copy(mass, 2.0);
  mfsi::Real3View f("test::f", 1);
  for (const double vx : {0.0, 1.0}) {
    auto hv = Kokkos::create_mirror_view(v);
    hv(0) = vx;
    hv(1) = hv(2) = 0;
    Kokkos::deep_copy(v, hv);
    pf.inertialForce(exec, x, v, mass, f);
    auto hf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f);
    const double expect[3] = {6 + 8 * vx, -5, -6};
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(hf(0, k), expect[k], Tol{1e-13, 0}, "f, v = " + std::to_string(vx)));
  }
}

// What the bodies receive from the same node moving in its frame: -m (Q a + 2 omega x Q v), the
// frame turned by 90 degrees about z (Q (1, 0, 0) = (0, 1, 0), Q (0, 1, 0) = (-1, 0, 0)), omega =
// (0, 0, 2), m = 2. With a = (0, 1, 3) and v = (1, 0, 0) in frame axes: Q a = (-1, 0, 3), Q v =
// (0, 1, 0), 2 omega x Q v = (-4, 0, 0), so f = -2 (-5, 0, 3). The frames' own acceleration and
// the lever terms (what the mass the bodies carry already answers) are not in it.
TEST(ParentFrames, RelativeInertiaOnTheBodies) {
  const cpl::ParentFrames pf = acceleratingTurnedFrame();
  const mfsi::ExecSpace exec;
  mfsi::RealView mass("test::mass", 1), v("test::v", 3), a("test::a", 3);
  Kokkos::deep_copy(mass, 2.0);
  auto hv = Kokkos::create_mirror_view(v);
  auto ha = Kokkos::create_mirror_view(a);
  hv(0) = 1, hv(1) = 0, hv(2) = 0;
  ha(0) = 0, ha(1) = 1, ha(2) = 3;
  Kokkos::deep_copy(v, hv);
  Kokkos::deep_copy(a, ha);
  mfsi::Real3View f("test::f", 1);
  pf.relativeInertia(exec, v, a, mass, f);
  auto hf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f);
  const double expect[3] = {10, 0, -6};
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(hf(0, k), expect[k], Tol{1e-13, 0}, "f"));
}
