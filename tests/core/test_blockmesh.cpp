#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/MeshGeometry.hpp"
#include "support/Approx.hpp"

using mfsi::test::near;
using mfsi::test::Tol;

namespace {
mfsi::BlockMeshSpec channel() {
  auto s = mfsi::boxSpec({0, 0, 0}, {2.0, 1.0, 0.5}, {8, 4, 3});
  s.blocks[0].grading = {2.0, 1.0, 0.5};
  s.blocks[0].patches = {"inlet", "outlet", "bottom", "top", "back", "front"};
  return s;
}
}  // namespace

TEST(BlockMesh, CountsOfASingleBox) {
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(channel()));
  const int nx = 8, ny = 4, nz = 3;
  EXPECT_EQ(m.nCells(), nx * ny * nz);
  EXPECT_EQ(m.nNodes(), (nx + 1) * (ny + 1) * (nz + 1));
  EXPECT_EQ(m.nInternalFaces(), (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1));
  EXPECT_EQ(m.nBoundaryFaces(), 2 * (nx * ny + ny * nz + nx * nz));
  ASSERT_EQ(m.patches().size(), 6u);
  EXPECT_EQ(m.patches()[m.patchIndex("inlet")].size, ny * nz);
  EXPECT_EQ(m.patches()[m.patchIndex("top")].size, nx * nz);
  EXPECT_THROW(m.patchIndex("inlte"), mfsi::InputError);
}

TEST(BlockMesh, VolumesSumToTheBoxAndFaceVectorsCloseEachCell) {
  auto spec = channel();
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
  // Distort the interior nodes so cells are general trilinear hexes.
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.points());
  for (int n = 0; n < m.nNodes(); ++n) {
    const double x = pts(n, 0), y = pts(n, 1), z = pts(n, 2);
    const bool interior = x > 1e-9 && x < 2 - 1e-9 && y > 1e-9 && y < 1 - 1e-9 && z > 1e-9 && z < 0.5 - 1e-9;
    if (interior) {
      pts(n, 0) += 0.03 * std::sin(7.0 * y + 3.0 * z);
      pts(n, 1) += 0.02 * std::cos(5.0 * x * z);
      pts(n, 2) += 0.01 * std::sin(4.0 * x + y);
    }
  }
  Kokkos::deep_copy(m.points(), pts);
  auto g = mfsi::allocateGeometry(m);
  mfsi::computeGeometry(mfsi::ExecSpace(), m, g);
  auto q = mfsi::computeQuality(mfsi::ExecSpace(), m, g);
  EXPECT_TRUE(near(q.totalVolume, 2.0 * 1.0 * 0.5, Tol{1e-13, 1e-13}, "total volume"));
  EXPECT_GT(q.minScaledJacobian, 0.0);
  EXPECT_LT(q.minScaledJacobian, 1.0);

  auto sf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceArea);
  auto own = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.faceOwner());
  auto nei = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.faceNeighbour());
  std::vector<std::array<double, 3>> sum(m.nCells(), {0, 0, 0});
  for (int f = 0; f < m.nFaces(); ++f)
    for (int k = 0; k < 3; ++k) {
      sum[own(f)][k] += sf(f, k);
      if (nei(f) >= 0) sum[nei(f)][k] -= sf(f, k);
    }
  for (int c = 0; c < m.nCells(); ++c)
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(near(sum[c][k], 0.0, Tol{1e-15, 0}, "cell " + std::to_string(c)));
}

TEST(BlockMesh, GluedBlocksShareTheirInterface) {
  mfsi::BlockMeshSpec s;
  mfsi::BlockSpec a, b;
  a.min = {0, 0, 0};
  a.max = {1, 1, 1};
  a.cells = {3, 2, 2};
  a.patches = {"left", "glue", "", "", "", ""};
  b.min = {1, 0, 0};
  b.max = {3, 1, 1};
  b.cells = {5, 2, 2};
  b.patches = {"glue", "right", "", "", "", ""};
  s.blocks = {a, b};
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(s));
  EXPECT_EQ(m.nCells(), 3 * 4 + 5 * 4);
  EXPECT_EQ(m.nNodes(), 9 * 3 * 3);
  EXPECT_EQ(m.findPatch("glue"), -1);
  EXPECT_EQ(m.patches()[m.patchIndex("left")].size, 4);
  EXPECT_EQ(m.patches()[m.patchIndex("right")].size, 4);
}

TEST(BlockMesh, BafflePatchesPairUpFaceByFace) {
  auto s = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {4, 4, 4});
  mfsi::BaffleRect br;
  br.name = "membrane";
  br.axis = 2;
  br.position = 0.5;
  br.min = {0.25, 0.0, 0};
  br.max = {0.75, 1.0, 0};
  s.baffles.push_back(br);
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(s));
  const auto& mp = m.patches()[m.patchIndex("membrane_master")];
  const auto& sp = m.patches()[m.patchIndex("membrane_slave")];
  ASSERT_EQ(mp.size, 2 * 4);
  ASSERT_EQ(sp.size, mp.size);
  EXPECT_EQ(mp.pairedPatch, m.patchIndex("membrane_slave"));
  EXPECT_EQ(m.nInternalFaces(), 3 * 4 * 4 * 3 - 8);
  auto g = mfsi::allocateGeometry(m);
  mfsi::computeGeometry(mfsi::ExecSpace(), m, g);
  auto sf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceArea);
  auto fc = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceCentroid);
  for (int i = 0; i < mp.size; ++i) {
    const int fm = mp.start + i, fs = sp.start + i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(near(fc(fm, k), fc(fs, k), Tol{1e-14, 0}, "paired centroid"));
      EXPECT_TRUE(near(sf(fm, k), -sf(fs, k), Tol{1e-14, 0}, "opposite normals"));
    }
    EXPECT_GT(sf(fm, 2), 0.0) << "master normal is the declared +z";
  }
}
