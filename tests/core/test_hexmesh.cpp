#include "core/HexMesh.hpp"
#include "core/Error.hpp"
#include "support/Approx.hpp"

namespace {
mfsi::HexMeshInput unitCube() {
  mfsi::HexMeshInput in;
  in.source = "cube";
  in.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  in.cells = {{0, 1, 2, 3, 4, 5, 6, 7}};
  return in;
}
}  // namespace

TEST(HexMesh, SingleCubeHasSixBoundaryFacesInDefaultPatch) {
  auto m = mfsi::buildHexMesh(unitCube());
  EXPECT_EQ(m.nCells(), 1);
  EXPECT_EQ(m.nFaces(), 6);
  EXPECT_EQ(m.nInternalFaces(), 0);
  ASSERT_EQ(m.patches().size(), 1u);
  EXPECT_EQ(m.patches()[0].name, "defaultFaces");
  EXPECT_EQ(m.patches()[0].size, 6);
}

TEST(HexMesh, InvertedCellIsRejected) {
  auto in = unitCube();
  std::swap(in.cells[0][1], in.cells[0][3]);
  std::swap(in.cells[0][5], in.cells[0][7]);
  EXPECT_THROW(mfsi::buildHexMesh(in), mfsi::InputError);
}
