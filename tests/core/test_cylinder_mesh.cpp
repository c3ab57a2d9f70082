// The Schaefer-Turek cylinder mesh (scripts/make_cylinder_mesh.py) read back through the Gmsh
// reader: a valid all-hex mesh with the benchmark's geometry and patches.
#include "core/GmshReader.hpp"
#include "core/HexMesh.hpp"
#include "core/MeshGeometry.hpp"
#include "support/Approx.hpp"

#include <cmath>

namespace {

using mfsi::test::near;
using mfsi::test::Tol;

TEST(CylinderMesh, CoarseSchaeferTurekMeshHasTheBenchmarkGeometry) {
  const auto mesh = mfsi::buildHexMesh(mfsi::readGmsh(std::string(MFSI_TEST_DATA_DIR) + "/meshes/cylinder_coarse.msh"));
  EXPECT_EQ(mesh.nCells(), 1888);
  const char* names[] = {"inlet", "outlet", "walls", "cylinder", "frontAndBack"};
  const int sizes[] = {25, 25, 128, 48, 2 * 1888};
  ASSERT_EQ(mesh.patches().size(), 5u);
  for (int p = 0; p < 5; ++p) {
    EXPECT_EQ(mesh.patches()[p].name, names[p]);
    EXPECT_EQ(mesh.patches()[p].size, sizes[p]) << names[p];
  }
  const auto geo = mfsi::allocateGeometry(mesh);
  const mfsi::ExecSpace exec;
  mfsi::computeGeometry(exec, mesh, geo);
  const auto q = mfsi::computeQuality(exec, mesh, geo);
  EXPECT_GT(q.minScaledJacobian, 0.7);  // 1/sqrt(2) at the corners of the O-grid square

  // The cylinder is a regular 48-gon of radius R inscribed in the circle (nodes on the circle).
  const double pi = 3.14159265358979323846, R = 0.05, H = 0.01;
  const int n = 48;
  const double polygonArea = 0.5 * n * R * R * std::sin(2 * pi / n);
  EXPECT_TRUE(near(q.totalVolume, (2.2 * 0.41 - polygonArea) * H, Tol{0, 1e-8}, "fluid volume"));

  auto area = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo.faceAreaMag);
  auto centroid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo.faceCentroid);
  const auto& cyl = mesh.patches()[mesh.patchIndex("cylinder")];
  double total = 0;
  for (mfsi::lid_t f = cyl.start; f < cyl.start + cyl.size; ++f) {
    total += area(f);
    const double r = std::hypot(centroid(f, 0) - 0.2, centroid(f, 1) - 0.2);
    EXPECT_TRUE(near(r, R * std::cos(pi / n), Tol{1e-9, 0}, "cylinder face centroid radius"));
    EXPECT_TRUE(near(centroid(f, 2), 0.5 * H, Tol{1e-12, 0}, "cylinder face centroid z"));
  }
  EXPECT_TRUE(near(total, n * 2 * R * std::sin(pi / n) * H, Tol{0, 1e-8}, "cylinder area"));
}

}  // namespace
