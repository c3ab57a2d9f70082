#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/MeshConfig.hpp"
#include "core/MeshGeometry.hpp"
#include "core/SceneConfig.hpp"
#include "support/Approx.hpp"

#include <unistd.h>

#include <string>
#include <vector>

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

// Touching blocks: conforming sides glue (also over part of a side when the grid lines meet there);
// sides whose grids differ are refused, naming both blocks, the sides and the cells on each.
namespace {
mfsi::BlockSpec block(std::array<double, 3> lo, std::array<double, 3> hi, std::array<int, 3> cells) {
  mfsi::BlockSpec b;
  b.min = lo;
  b.max = hi;
  b.cells = cells;
  return b;
}

mfsi::BlockMeshSpec twoBlocks(const mfsi::BlockSpec& a, const mfsi::BlockSpec& b) {
  mfsi::BlockMeshSpec s;
  s.blocks = {a, b};
  return s;
}

std::string generateError(const mfsi::BlockMeshSpec& s) {
  try {
    mfsi::generateBlockMesh(s);
  } catch (const mfsi::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

#define EXPECT_HAS(msg, part) EXPECT_NE((msg).find(part), std::string::npos) << "'" << (part) << "' not in: " << (msg)
}  // namespace

TEST(BlockMesh, PartlyTouchingBlocksGlueWhereTheirGridLinesMeet) {
  // B sits on the left half of A's +y side; A's x grid lines 0, 0.5, 1 are B's.
  const auto s = twoBlocks(block({0, 0, 0}, {2, 1, 1}, {4, 2, 2}), block({0, 1, 0}, {1, 2, 1}, {2, 2, 2}));
  EXPECT_FALSE(mfsi::findMismatchedContact(s).has_value());
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(s));
  EXPECT_EQ(m.nCells(), 16 + 8);
  EXPECT_EQ(m.nNodes(), 5 * 3 * 3 + 3 * 3 * 3 - 3 * 3);
  EXPECT_EQ(m.nInternalFaces(), (3 * 2 * 2 + 4 * 1 * 2 + 4 * 2 * 1) + (1 * 2 * 2 + 2 * 1 * 2 + 2 * 2 * 1) + 2 * 2);
}

TEST(BlockMesh, BlocksMeetingAtAnEdgeOnlyNeedNoCommonGrid) {
  const auto s = twoBlocks(block({0, 0, 0}, {1, 1, 1}, {4, 4, 4}), block({1, 1, 0}, {2, 2, 1}, {3, 3, 3}));
  EXPECT_FALSE(mfsi::findMismatchedContact(s).has_value());
  EXPECT_EQ(mfsi::buildHexMesh(mfsi::generateBlockMesh(s)).nCells(), 64 + 27);
}

TEST(BlockMesh, TouchingSidesWithDifferentCellsAreRefused) {
  const auto s = twoBlocks(block({0, 0, 0}, {1, 1, 1}, {4, 4, 2}), block({1, 0, 0}, {2, 1, 1}, {4, 2, 2}));
  const auto m = mfsi::findMismatchedContact(s);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->block[0], 0u);
  EXPECT_EQ(m->block[1], 1u);
  EXPECT_EQ(m->side[0], mfsi::BoxSide::XMax);
  EXPECT_EQ(m->side[1], mfsi::BoxSide::XMin);
  EXPECT_EQ(m->along[0], 1);
  EXPECT_EQ(m->along[1], 2);
  EXPECT_EQ(m->cells[0][0], 4);
  EXPECT_EQ(m->cells[1][0], 2);
  EXPECT_EQ(m->cause, mfsi::BlockMismatch::Cause::Cells);
  const std::string msg = generateError(s);
  EXPECT_HAS(msg,
             "block 0 face +x and block 1 face -x touch but their grids differ: 4x2 cells against 2x2 cells (y x z)");
  EXPECT_HAS(msg, "give both the same cells on the shared face");

  // Listed the other way round, and touching along z.
  const auto r = twoBlocks(block({0, 0, 1}, {1, 1, 2}, {3, 3, 1}), block({0, 0, 0}, {1, 1, 1}, {2, 3, 1}));
  EXPECT_HAS(generateError(r),
             "block 0 face -z and block 1 face +z touch but their grids differ: 3x3 cells against "
             "2x3 cells (x x y)");
}

TEST(BlockMesh, TouchingSidesWithDifferentGradingAreRefused) {
  auto b = block({0, 0, 0}, {1, 1, 1}, {2, 4, 2});
  b.grading = {1, 3, 1};
  const auto s = twoBlocks(block({1, 0, 0}, {2, 1, 1}, {2, 4, 2}), b);
  const auto m = mfsi::findMismatchedContact(s);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cause, mfsi::BlockMismatch::Cause::Grading);
  EXPECT_HAS(generateError(s),
             "block 0 face -x and block 1 face +x touch with the same 4x2 cells (y x z) but their "
             "grids differ (different grading)");
  // Grading across the shared side (along x here) does not matter.
  auto c = block({0, 0, 0}, {1, 1, 1}, {5, 4, 2});
  c.grading = {4, 1, 1};
  EXPECT_FALSE(mfsi::findMismatchedContact(twoBlocks(block({1, 0, 0}, {2, 1, 1}, {2, 4, 2}), c)).has_value());
}

TEST(BlockMesh, PartlyTouchingSidesWhoseGridLinesMissEachOtherAreRefused) {
  // A's y grid lines are 0, 0.25, ...; B ends at y = 0.6, between two of them.
  const auto s = twoBlocks(block({0, 0, 0}, {1, 1, 1}, {2, 4, 2}), block({1, 0, 0}, {2, 0.6, 1}, {2, 3, 2}));
  const auto m = mfsi::findMismatchedContact(s);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cause, mfsi::BlockMismatch::Cause::Extent);
  EXPECT_HAS(generateError(s),
             "block 0 face +x and block 1 face -x touch on part of their faces but their grids "
             "differ there (3x2 cells against 3x2 cells (y x z)");
}

TEST(BlockMesh, CountsBeforeAllocating) {
  const auto c = mfsi::countBlock(block({0, 0, 0}, {1, 1, 1}, {8, 4, 3}));
  EXPECT_EQ(c.cells, 96);
  EXPECT_EQ(c.nodes, 9 * 5 * 4);
  EXPECT_EQ(c.faces, 9 * 4 * 3 + 8 * 5 * 3 + 8 * 4 * 4);
  EXPECT_EQ(c.largest(), c.faces);
  // 10^15 cells: refused at once, nothing allocated.
  const auto huge = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {100000, 100000, 100000});
  EXPECT_EQ(mfsi::countBlockMesh(huge).cells, 1e15);
  EXPECT_HAS(generateError(huge), "more than the 2147483647 one rank can index (lid_t)");
}

// The config layer locates these errors in the scene: the key to fix of each block, --set included.
namespace {
const char* kTwoBlocks =
    "mesh:\n"
    "  blocks:\n"
    "    - min: [0.0, 0.0, 0.0]\n"
    "      max: [1.0, 0.5, 0.5]\n"
    "      cells: [20, 10, 10]\n"
    "    - min: [1.0, 0.0, 0.0]\n"
    "      max: [3.0, 0.5, 0.5]\n"
    "      cells: [30, 10, 10]\n";

std::string meshError(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  const auto schema = mfsi::Schema::map("scene").key("mesh", mfsi::meshSchema());
  try {
    const auto cfg = mfsi::SceneConfig::fromString(yaml, "scene.yaml", schema, overrides);
    mfsi::buildMesh(cfg.child("mesh"));
  } catch (const mfsi::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}
}  // namespace

TEST(MeshConfig, MismatchedBlocksNameBothBlocksWhereTheyAreGiven) {
  const auto schema = mfsi::Schema::map("scene").key("mesh", mfsi::meshSchema());
  const auto ok = mfsi::SceneConfig::fromString(kTwoBlocks, "scene.yaml", schema, {"mesh.blocks.0.cells=[32,10,10]"});
  EXPECT_EQ(mfsi::buildMesh(ok.child("mesh")).nCells(), 3200 + 3000);

  const std::string msg = meshError(kTwoBlocks, {"mesh.blocks.0.cells=[32,32,8]"});
  EXPECT_HAS(msg, "--set mesh.blocks.0.cells=[32,32,8]: key 'mesh.blocks.0.cells': ");
  EXPECT_HAS(msg,
             "mesh.blocks.0 face +x and mesh.blocks.1 face -x touch but their grids differ: 32x8 cells against "
             "10x10 cells (y x z)");
  EXPECT_HAS(msg, "mesh.blocks.1.cells is at scene.yaml:8:");

  std::string graded = kTwoBlocks;
  graded += "      grading: [1, 2, 1]\n";
  const std::string g = meshError(graded);
  EXPECT_HAS(g, "scene.yaml:3:");  // block 0 has no grading key: its closest given key
  EXPECT_HAS(g, "different grading");
  EXPECT_HAS(g, "mesh.blocks.1.grading is at scene.yaml:9:");
}

TEST(MeshConfig, MeshesTooLargeToIndexOrToHoldAreRefusedBeforeAllocating) {
  const std::string huge = meshError(kTwoBlocks, {"mesh.blocks.1.cells=[100000,100000,100000]"});
  EXPECT_HAS(huge,
             "--set mesh.blocks.1.cells=[100000,100000,100000]: key 'mesh.blocks.1.cells': cells [100000, "
             "100000, 100000] (the largest of 2 blocks) make a mesh of 1e+15 cells");
  EXPECT_HAS(huge, "(lid_t is 32-bit)");

  // 5.12e8 cells fit lid_t (1.5e9 faces) but need ~2.5 TB.
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0 && static_cast<double>(pages) * pageSize > 2e12)
    GTEST_SKIP() << "this machine has more than 2 TB of memory";
  const std::string big = meshError(kTwoBlocks, {"mesh.blocks.0.cells=[800,800,800]"});
  EXPECT_HAS(big,
             "key 'mesh.blocks.0.cells': cells [800, 800, 800] (the largest of 2 blocks) make a mesh of "
             "512003000 cells");
  EXPECT_HAS(big, "TB (mesh and solver fields, ~5 kB per cell), more than the ");
  EXPECT_HAS(big, "of memory of this machine");
}

// mesh.refine: every block's cells times a factor, so a study varies one key for any scene.
TEST(BlockMesh, RefineMultipliesCellsAndKeepsTheThicknessOfA2DScene) {
  // A 2D scene: one cell in z in every block.
  auto s = twoBlocks(block({0, 0, 0}, {1, 1, 0.1}, {4, 3, 1}), block({1, 0, 0}, {3, 1, 0.1}, {6, 3, 1}));
  s.blocks[0].grading = {2, 1, 1};
  auto fine = s;
  mfsi::refineBlocks(fine, 2);
  EXPECT_EQ(fine.blocks[0].cells, (std::array<int, 3>{8, 6, 1}));
  EXPECT_EQ(fine.blocks[1].cells, (std::array<int, 3>{12, 6, 1}));
  EXPECT_EQ(fine.blocks[0].grading, s.blocks[0].grading);
  // Still glued along x = 1: the refined interface grids match.
  EXPECT_FALSE(mfsi::findMismatchedContact(fine).has_value());
  EXPECT_EQ(mfsi::buildHexMesh(mfsi::generateBlockMesh(fine)).nCells(), 8 * 6 + 12 * 6);

  // Rounded to the nearest count (half away from zero), never below one cell.
  auto odd = s;
  mfsi::refineBlocks(odd, 1.5);
  EXPECT_EQ(odd.blocks[0].cells, (std::array<int, 3>{6, 5, 1}));  // 4.5 -> 5
  EXPECT_EQ(odd.blocks[1].cells, (std::array<int, 3>{9, 5, 1}));
  auto coarse = s;
  mfsi::refineBlocks(coarse, 0.1);
  EXPECT_EQ(coarse.blocks[0].cells, (std::array<int, 3>{1, 1, 1}));
  EXPECT_EQ(coarse.blocks[1].cells, (std::array<int, 3>{1, 1, 1}));

  // A direction with one cell in one block only is refined like the others (a thin 3D layer).
  auto layer = twoBlocks(block({0, 0, 0}, {1, 0.1, 1}, {4, 1, 4}), block({0, 0.1, 0}, {1, 1, 1}, {4, 5, 4}));
  mfsi::refineBlocks(layer, 2);
  EXPECT_EQ(layer.blocks[0].cells, (std::array<int, 3>{8, 2, 8}));
  EXPECT_EQ(layer.blocks[1].cells, (std::array<int, 3>{8, 10, 8}));
}

TEST(BlockMesh, RefineRefusesFactorsThatAreNotPositiveOrOverflow) {
  for (const double f : {0.0, -1.0, std::nan("")}) {
    auto s = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
    EXPECT_THROW(mfsi::refineBlocks(s, f), mfsi::InputError) << f;
  }
  auto s = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  try {
    mfsi::refineBlocks(s, 2e9);
    ADD_FAILURE() << "expected an InputError";
  } catch (const mfsi::InputError& e) {
    EXPECT_HAS(std::string(e.what()), "more than 2147483647");
  }
}

TEST(MeshConfig, RefineKeyScalesTheBlocksAndIsRefusedWhereItCannotApply) {
  const auto schema = mfsi::Schema::map("scene").key("mesh", mfsi::meshSchema());
  const auto plain = mfsi::SceneConfig::fromString(kTwoBlocks, "scene.yaml", schema);
  EXPECT_EQ(plain.get<double>("mesh.refine"), 1.0);
  EXPECT_EQ(mfsi::buildMesh(plain.child("mesh")).nCells(), 2000 + 3000);
  const auto half = mfsi::SceneConfig::fromString(kTwoBlocks, "scene.yaml", schema, {"mesh.refine=0.5"});
  EXPECT_EQ(mfsi::buildMesh(half.child("mesh")).nCells(), 10 * 5 * 5 + 15 * 5 * 5);

  EXPECT_HAS(meshError(kTwoBlocks, {"mesh.refine=0"}), "mesh.refine");
  // The size check says the cells it refuses come from the factor.
  EXPECT_HAS(meshError(kTwoBlocks, {"mesh.refine=5000"}),
             "key 'mesh.blocks.1.cells': cells [150000, 50000, 50000] (the largest of 2 blocks) (after mesh.refine = "
             "5000) make a mesh of");
  // A mesh file is not generated here: refining it is refused, naming the key.
  const std::string fromFile = meshError("mesh:\n  file: " MFSI_TEST_DATA_DIR "/meshes/box.msh\n  refine: 2\n");
  EXPECT_HAS(fromFile, "key 'mesh.refine'");
  EXPECT_HAS(fromFile, "refine multiplies the cells of generated 'blocks'");
}
