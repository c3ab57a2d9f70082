#include "core/HexGeometry.hpp"
#include "core/HexMesh.hpp"
#include "core/Error.hpp"
#include "support/Approx.hpp"

#include <algorithm>
#include <cmath>

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

TEST(HexGeometry, VolumeAndCentroidOfDistortedHexesAreExact) {
  // Random trilinear hexes (corners of the unit cube moved by up to 0.3 in each direction, some
  // faces warped): the closed form and the 2x2x2 Gauss sum (exact for a trilinear map) agree to
  // round-off; a sheared, twisted cell whose volume is known exactly checks the value itself.
  const double s[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  unsigned state = 12345;
  auto uniform = [&]() {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1u << 24) - 0.5;  // [-0.5, 0.5)
  };
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    double x[8][3];
    for (int q = 0; q < 8; ++q)
      for (int k = 0; k < 3; ++k) x[q][k] = s[q][k] + 0.6 * uniform();
    double v, c[3];
    mfsi::geom::hexVolumeCentroid(x, v, c);
    worst = std::max(worst, std::abs(mfsi::geom::hexVolume(x) - v) / std::abs(v));
  }
  EXPECT_LT(worst, 1e-13);
  // x' = x + 0.3 y + 0.2 z, y' = 2 y, z' = z + 0.5 x y (sheared and warped): det J = 2 - 0.2 y,
  // whose integral over the unit cube is 1.9; the centroid (integrals of x' det J / 1.9) is
  // (71/95, 56/57, 71/114).
  double t[8][3];
  for (int q = 0; q < 8; ++q) {
    const double X = s[q][0], Y = s[q][1], Z = s[q][2];
    t[q][0] = X + 0.3 * Y + 0.2 * Z;
    t[q][1] = 2 * Y;
    t[q][2] = Z + 0.5 * X * Y;
  }
  EXPECT_NEAR(mfsi::geom::hexVolume(t), 1.9, 1e-14);
  double v, c[3];
  mfsi::geom::hexVolumeCentroid(t, v, c);
  EXPECT_NEAR(v, 1.9, 1e-14);
  EXPECT_NEAR(c[0], 71.0 / 95, 1e-14);
  EXPECT_NEAR(c[1], 56.0 / 57, 1e-14);
  EXPECT_NEAR(c[2], 71.0 / 114, 1e-14);
}

TEST(HexGeometry, QuadCentroidOfATrapezoidIsExact) {
  // Bottom 2, top 1, height 1, tilted out of the xy plane by rotating about the x axis by 30
  // degrees: area 1.5, centroid at (1, 4/9) in the trapezoid's plane.
  const double cs = std::cos(M_PI / 6), sn = std::sin(M_PI / 6);
  const double p[4][2] = {{0, 0}, {2, 0}, {1.5, 1}, {0.5, 1}};
  double x[4][3];
  for (int q = 0; q < 4; ++q) {
    x[q][0] = p[q][0];
    x[q][1] = cs * p[q][1];
    x[q][2] = sn * p[q][1];
  }
  double c[3], area;
  mfsi::geom::quadCentroid(x, c, area);
  EXPECT_NEAR(area, 1.5, 1e-14);
  EXPECT_NEAR(c[0], 1.0, 1e-14);
  EXPECT_NEAR(c[1], cs * 4.0 / 9, 1e-14);
  EXPECT_NEAR(c[2], sn * 4.0 / 9, 1e-14);
}
