// Mesh motion by displacement smoothing: zero motion is exact, a large wall deflection keeps every
// cell valid, an impossible one is refused with the mesh left as it was.
#include "coupling/motion/MeshSmoother.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using mfsi::lid_t;
using mfsi::coupling::MeshSmoother;
using mfsi::coupling::MeshSmootherOptions;

namespace {

mfsi::HexMesh gradedBox(int n, double gz) {
  mfsi::BlockMeshSpec spec = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].grading = {1, 1, gz};
  return mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
}

/// Bottom-wall nodes (z = 0) get the upward bump a sin(pi x) sin(pi y); every other entry is zeroed.
void bottomBump(const MeshSmoother& s, const mfsi::HexMesh& mesh, double a) {
  auto hd = Kokkos::create_mirror_view(s.displacement());
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    hd(i, 0) = hd(i, 1) = hd(i, 2) = 0;
    if (std::abs(hx(i, 2)) < 1e-12) hd(i, 2) = a * std::sin(M_PI * hx(i, 0)) * std::sin(M_PI * hx(i, 1));
  }
  Kokkos::deep_copy(s.displacement(), hd);
}

/// The nodes whose reference point lies on the surface z = surface(x, y) (to 1e-12).
template <class Surface>
std::vector<mfsi::gid_t> nodesOn(const mfsi::HexMesh& mesh, Surface surface) {
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  std::vector<mfsi::gid_t> nodes;
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    if (std::abs(hx(i, 2) - surface(hx(i, 0), hx(i, 1))) < 1e-12) nodes.push_back(i);
  return nodes;
}

/// The columns' feet take their nodes' displacement (a whole mesh: a node's global id is its index).
void placeFeet(const MeshSmoother& s, const std::vector<mfsi::gid_t>& feet) {
  auto d = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.displacement());
  auto f = Kokkos::create_mirror_view(s.columnFeet());
  for (std::size_t j = 0; j < feet.size(); ++j)
    for (int c = 0; c < 3; ++c) f(j, c) = d(feet[j], c);
  Kokkos::deep_copy(s.columnFeet(), f);
}

/// Thickness of the first cell row of a box of n cells graded gz along z.
double firstCellThickness(int n, double gz) {
  const double r = std::pow(gz, 1.0 / (n - 1));
  return (r - 1) / (std::pow(r, n) - 1);
}

}  // namespace

TEST(MeshMotion, ZeroMotionLeavesAGradedMeshBitIdentical) {
  auto mesh = gradedBox(10, 8);
  MeshSmoother s(mesh, MeshSmootherOptions{});
  mfsi::ExecSpace exec;
  const auto rep = s.move(exec);
  exec.fence();
  EXPECT_EQ(rep.retries, 0);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
  auto h0 = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(hx(i, c), h0(i, c)) << "node " << i;
}

TEST(MeshMotion, AWallDeflectionOfFiveCellThicknessesKeepsEveryCellValid) {
  const int n = 16;
  const double gz = 8, h0 = firstCellThickness(n, gz);
  auto mesh = gradedBox(n, gz);
  MeshSmoother s(mesh, MeshSmootherOptions{});
  bottomBump(s, mesh, 5 * h0);
  mfsi::ExecSpace exec;
  const auto rep = s.move(exec);
  EXPECT_GT(rep.minScaledJacobian, MeshSmootherOptions{}.minScaledJacobian);
  // The wall really moved by 5 first-cell thicknesses at its centre (node at x = y = 0.5).
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
  auto hr = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  double top = 0;
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    if (std::abs(hr(i, 2)) < 1e-12) top = std::max(top, hx(i, 2));
  EXPECT_NEAR(top, 5 * h0, 1e-12);
  // Moving only the wall nodes (no smoothing) would invert the first cell rows.
  MeshSmootherOptions noSweeps;
  noSweeps.sweeps = 0;
  noSweeps.retries = 0;
  MeshSmoother none(mesh, noSweeps);
  bottomBump(none, mesh, 5 * h0);
  EXPECT_THROW(none.move(exec), mfsi::DivergenceError);
}

TEST(MeshMotion, SolvedMotionLeavesAGradedMeshBitIdenticalAndKeepsALargeWallDeflectionValid) {
  const int n = 16;
  const double gz = 8, h0 = firstCellThickness(n, gz);
  auto mesh = gradedBox(n, gz);
  MeshSmootherOptions o;
  o.method = mfsi::coupling::MeshMotionMethod::ConjugateGradient;
  MeshSmoother s(mesh, o);
  mfsi::ExecSpace exec;
  EXPECT_EQ(s.move(exec).sweeps, 0);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
  auto h0v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(hx(i, c), h0v(i, c)) << "node " << i;
  // A deflection of 12 first-cell thicknesses: 50 sweeps carry it into the first cell rows alone,
  // the solved motion spreads it over the box.
  MeshSmootherOptions once;
  once.retries = 0;
  once.minScaledJacobian = 0;
  MeshSmoother sweeps(mesh, once);
  bottomBump(sweeps, mesh, 12 * h0);
  EXPECT_THROW(sweeps.move(exec), mfsi::DivergenceError) << "50 sweeps invert the first cell rows";
  bottomBump(s, mesh, 12 * h0);
  const auto rep = s.move(exec);
  std::printf("solved motion: min scaled Jacobian %.3f after %d CG iterations\n", rep.minScaledJacobian, rep.sweeps);
  EXPECT_GT(rep.minScaledJacobian, 0.3);
  EXPECT_EQ(rep.retries, 0);
}

TEST(MeshMotion, AnImpossibleMotionIsRefusedAndTheMeshKeptAsItWas) {
  auto mesh = gradedBox(8, 4);
  MeshSmoother s(mesh, MeshSmootherOptions{});
  mfsi::ExecSpace exec;
  bottomBump(s, mesh, 0.05);  // an accepted motion first
  s.move(exec);
  exec.fence();
  // Own host copies (a mirror of a host View would be the mesh's points themselves).
  Kokkos::View<double* [3], Kokkos::HostSpace> before("before", mesh.nNodes()), after("after", mesh.nNodes());
  Kokkos::deep_copy(before, mesh.points());
  bottomBump(s, mesh, 1.5);  // through the fixed top wall: no interior motion can save it
  EXPECT_THROW(s.move(exec), mfsi::DivergenceError);
  Kokkos::deep_copy(after, mesh.points());
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(after(i, c), before(i, c)) << "node " << i;
}

TEST(MeshMotion, ColumnsCarryTheWallMotionLinearlyInArcLength) {
  // A box graded 8:1 along z, its bottom wall pushed up by a bump of 0.4 (17 first-cell thicknesses):
  // with columns, every interior node above a bottom node moves by the bump times 1 - s / S (s its
  // reference height, S the column's length 1), exactly; every cell stays valid.
  const int n = 12;
  auto mesh = gradedBox(n, 8);
  MeshSmootherOptions o;
  o.method = mfsi::coupling::MeshMotionMethod::ConjugateGradient;
  o.columns = true;
  MeshSmoother s(mesh, o);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  std::vector<mfsi::gid_t> feet;
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    if (std::abs(hx(i, 2)) < 1e-12) feet.push_back(i);
  // Feet on the side walls have their one leaving edge on the wall (a boundary node): no column.
  EXPECT_EQ(s.setColumnFeet(feet), (n - 1) * (n - 1));
  const double a = 0.4;
  bottomBump(s, mesh, a);
  placeFeet(s, feet);
  mfsi::ExecSpace exec;
  const auto rep = s.move(exec);
  exec.fence();
  std::printf("columns: min scaled Jacobian %.3f\n", rep.minScaledJacobian);
  EXPECT_GT(rep.minScaledJacobian, 0.3);
  auto hd = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.displacement());
  auto fixed = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.prescribed());
  int checked = 0;
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    const double x = hx(i, 0), y = hx(i, 1), z = hx(i, 2);
    const bool interior = x > 1e-12 && x < 1 - 1e-12 && y > 1e-12 && y < 1 - 1e-12 && z > 1e-12 && z < 1 - 1e-12;
    if (!interior) continue;
    EXPECT_EQ(fixed(i), 1) << "node " << i;
    const double expected = a * std::sin(M_PI * x) * std::sin(M_PI * y) * (1 - z);
    EXPECT_NEAR(hd(i, 2), expected, 1e-14 + 1e-12 * std::abs(expected)) << "node " << i;
    EXPECT_EQ(hd(i, 0), 0.0);
    ++checked;
  }
  EXPECT_EQ(checked, (n - 1) * (n - 1) * (n - 1));
  // The same bump without columns folds a cell of the thin first rows.
  MeshSmootherOptions plain = o;
  plain.columns = false;
  auto mesh2 = gradedBox(n, 8);
  MeshSmoother s2(mesh2, plain);
  bottomBump(s2, mesh2, a);
  EXPECT_THROW(s2.move(exec), mfsi::DivergenceError);
}

TEST(MeshMotion, ColumnsRunThroughLayersThatSlope) {
  // Vertical lines of edges through layers that slope by 40 degrees (z + tan(40) x: a housing
  // and a membrane near their rim): each line's next edge is the vertical one, the layers' own
  // edges 50 degrees off it. Every interior node carries a column; at 65 degrees (the layers'
  // edges 25 degrees off) none does.
  const int n = 6;
  auto sloped = [&](double degrees) {
    mfsi::HexMeshInput in = mfsi::generateBlockMesh(mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n}));
    for (auto& p : in.points) p[2] += std::tan(degrees * M_PI / 180) * p[0];
    return mfsi::buildHexMesh(in);
  };
  for (const double degrees : {40.0, 65.0}) {
    const auto mesh = sloped(degrees);
    MeshSmootherOptions o;
    o.columns = true;
    MeshSmoother s(mesh, o);
    const auto feet = nodesOn(mesh, [&](double x, double) { return std::tan(degrees * M_PI / 180) * x; });
    ASSERT_EQ(feet.size(), static_cast<std::size_t>((n + 1) * (n + 1)));
    EXPECT_EQ(s.setColumnFeet(feet), degrees < 60 ? (n - 1) * (n - 1) : 0) << degrees << " degrees";
  }
}

TEST(MeshMotion, ABafflesNodesCarryAColumnOnEachSide) {
  // A baffle across the middle of a box (z = 0.5) pushed up by a bump: each interior baffle node
  // has a column up to the lid and one down to the floor, and every node on them moves by the bump
  // times 1 - |z - 0.5| / 0.5, exactly.
  const int n = 6;
  mfsi::BlockMeshSpec spec = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  mfsi::BaffleRect b;
  b.name = "sheet";
  b.axis = 2;
  b.position = 0.5;
  b.min = {0, 0, 0.5};
  b.max = {1, 1, 0.5};
  spec.baffles.push_back(b);
  const auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
  MeshSmootherOptions o;
  o.columns = true;
  MeshSmoother s(mesh, o);
  const auto feet = nodesOn(mesh, [](double, double) { return 0.5; });
  EXPECT_EQ(s.setColumnFeet(feet), 2 * (n - 1) * (n - 1));
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  const double a = 0.2;
  auto hd = Kokkos::create_mirror_view(s.displacement());
  auto bump = [&](lid_t i) { return a * std::sin(M_PI * hx(i, 0)) * std::sin(M_PI * hx(i, 1)); };
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    hd(i, 0) = hd(i, 1) = hd(i, 2) = 0;
    if (std::abs(hx(i, 2) - 0.5) < 1e-12) hd(i, 2) = bump(i);
  }
  Kokkos::deep_copy(s.displacement(), hd);
  placeFeet(s, feet);
  mfsi::ExecSpace exec;
  const auto rep = s.move(exec);
  exec.fence();
  EXPECT_GT(rep.minScaledJacobian, 0.3);
  Kokkos::deep_copy(hd, s.displacement());
  int checked = 0;
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    const double x = hx(i, 0), y = hx(i, 1), z = hx(i, 2);
    if (x < 1e-12 || x > 1 - 1e-12 || y < 1e-12 || y > 1 - 1e-12 || z < 1e-12 || z > 1 - 1e-12) continue;
    if (std::abs(z - 0.5) < 1e-12) continue;
    const double expected = bump(i) * (1 - std::abs(z - 0.5) / 0.5);
    EXPECT_NEAR(hd(i, 2), expected, 1e-14 + 1e-12 * std::abs(expected)) << "node " << i;
    ++checked;
  }
  EXPECT_EQ(checked, (n - 1) * (n - 1) * (n - 2));
}

TEST(MeshMotion, ColumnsStopWhereTheLineTurnsOrMeetsAnotherColumn) {
  // Feet on two opposite walls: the columns from the bottom (the earlier feet) run up to the top
  // wall (a boundary node), so those from the top, which run down through the same nodes, are left
  // to the Laplacian.
  auto mesh = gradedBox(6, 1);
  MeshSmootherOptions o;
  o.columns = true;
  MeshSmoother s(mesh, o);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  std::vector<mfsi::gid_t> bottom, both;
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    if (std::abs(hx(i, 2)) < 1e-12) bottom.push_back(i);
    if (std::abs(hx(i, 2)) < 1e-12 || std::abs(hx(i, 2) - 1) < 1e-12) both.push_back(i);
  }
  EXPECT_EQ(s.setColumnFeet(both), 5 * 5);
  MeshSmoother none(mesh, MeshSmootherOptions{});
  EXPECT_EQ(none.setColumnFeet(bottom), 0);  // columns off
}
