// Fluid regions (FluidOptions::regions): the cells a patch reaches without crossing a baffle hold a
// fluid of their own (the VAD's air chamber beside its blood). Two checks that a region's density
// or viscosity taken from the rest of the mesh breaks:
//  - hydrostatics: two columns parted by a baffle, open at the top, under gravity: each column's
//    pressure is rho_i g (H - z) (a linear field the finite volumes represent: to 1e-6 rho_i g H);
//  - dynamic similarity: two channels parted by a baffle, fed alike, one fluid 4 times as dense and
//    4 times as viscous as the other (the same kinematic viscosity): the velocity fields are the
//    same (mirrored) and the second pressure is 4 times the first, at every time step.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/Loads.hpp"
#include "support/Approx.hpp"
#include "support/FluidRegionCases.hpp"

#include <cmath>
#include <map>
#include <tuple>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

FluidOptions tight(FluidOptions o) {
  o.momentumSolver = {1e-13, 0.0, 1000};
  o.pressureSolver = {1e-13, 0.0, 5000};
  return o;
}

}  // namespace

TEST(FluidRegions, EachColumnIsHydrostaticWithItsOwnDensity) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {8, 4, 4});
  spec.blocks[0].patches = {"left", "right", "wall", "wall", "wall", "top"};
  spec.baffles.push_back(BaffleRect{"panel", 0, 1.0, {1, 0, 0}, {1, 1, 1}});
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.density = 1000;
  o.viscosity = 1e-3;
  o.bodyForce = {0, 0, -9.81};
  o.regions.push_back({"right", 1.2, 1.8e-5});
  for (const char* w : {"left", "right", "wall"}) o.boundaries[w].type = BoundaryType::Wall;
  o.boundaries["top"].type = BoundaryType::FixedPressure;
  FluidSolver fluid(mesh, tight(o));
  for (int s = 0; s < 3; ++s) ASSERT_TRUE(fluid.solveStep(s * 0.01, 0.01).ok);
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  auto phi = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceFlux());
  int air = 0;
  for (lid_t c = 0; c < mesh.nCells(); ++c) {
    const double rho = C(c, 0) > 1 ? 1.2 : 1000.0;
    air += C(c, 0) > 1 ? 1 : 0;
    const double expected = rho * 9.81 * (1 - C(c, 2));
    EXPECT_NEAR(p(c), expected, 1e-6 * rho * 9.81) << "cell " << c << " at x = " << C(c, 0) << ", z = " << C(c, 2);
  }
  // At rest: no face passes anything. (The cell velocities next to the open top are not zero: the
  // cell gradient there sees the boundary's pressure, as without regions.)
  for (lid_t f = 0; f < mesh.nFaces(); ++f) EXPECT_NEAR(phi(f), 0.0, 1e-8) << "face " << f;
  EXPECT_EQ(air, mesh.nCells() / 2);
  // Each fluid's volume mean (fluid.meanPressure with regions): rho_i g H / 2.
  EXPECT_NEAR(meanPressure(fluid, fluid.cellFluidIndex(), -1), 1000 * 9.81 * 0.5, 1e-6 * 1000 * 9.81);
  EXPECT_NEAR(meanPressure(fluid, fluid.cellFluidIndex(), 0), 1.2 * 9.81 * 0.5, 1e-6 * 1.2 * 9.81);
  EXPECT_NEAR(meanPressure(fluid), (1000 + 1.2) * 9.81 * 0.25, 1e-6 * 1000 * 9.81);
}

TEST(FluidRegions, TwoChannelsOfOneKinematicViscosityFlowAlike) {
  // Channel B is channel A mirrored in the baffle's plane y = 0.5 (support/FluidRegionCases.hpp).
  HexMesh mesh = buildHexMesh(test::twoChannels());
  const FluidOptions o = test::twoChannelOptions();
  FluidSolver fluid(mesh, tight(o));
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  std::map<std::tuple<long, long, long>, lid_t> at;  // cell by its centroid, to 1e-6 m
  auto key = [](double x, double y, double z) {
    return std::make_tuple(std::lround(x * 1e6), std::lround(y * 1e6), std::lround(z * 1e6));
  };
  for (lid_t c = 0; c < mesh.nCells(); ++c) at[key(C(c, 0), C(c, 1), C(c, 2))] = c;
  for (int s = 0; s < 8; ++s) {
    ASSERT_TRUE(fluid.solveStep(s * 0.05, 0.05).ok);
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
    auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
    double pMax = 0, uMax = 0;
    for (lid_t c = 0; c < mesh.nCells(); ++c) {
      pMax = std::max(pMax, std::abs(p(c)));
      uMax = std::max(uMax, std::abs(U(c, 0)));
    }
    ASSERT_GT(pMax, 0.01);
    ASSERT_GT(uMax, 0.2);
    int pairs = 0;
    for (lid_t c = 0; c < mesh.nCells(); ++c) {
      if (C(c, 1) > 0.5) continue;
      const auto m = at.find(key(C(c, 0), 1 - C(c, 1), C(c, 2)));
      ASSERT_NE(m, at.end()) << "no mirror of cell " << c;
      const lid_t d = m->second;
      ++pairs;
      EXPECT_NEAR(p(d), 4 * p(c), 1e-8 * pMax) << "step " << s << ", cell " << c;
      EXPECT_NEAR(U(d, 0), U(c, 0), 1e-9 * uMax) << "step " << s << ", cell " << c;
      EXPECT_NEAR(U(d, 1), -U(c, 1), 1e-9 * uMax) << "step " << s << ", cell " << c;
      EXPECT_NEAR(U(d, 2), U(c, 2), 1e-9 * uMax) << "step " << s << ", cell " << c;
    }
    EXPECT_EQ(pairs, mesh.nCells() / 2);
  }
}

TEST(FluidRegions, TwoRegionsOfOneFluidRegionAreAnError) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {4, 2, 2});
  spec.blocks[0].patches = {"left", "right", "wall", "wall", "wall", "top"};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));  // no baffle: one region
  FluidOptions o;
  o.regions.push_back({"left", 1.2, 1.8e-5});
  o.regions.push_back({"right", 2.0, 1.8e-5});
  for (const char* w : {"left", "right", "wall"}) o.boundaries[w].type = BoundaryType::Wall;
  o.boundaries["top"].type = BoundaryType::FixedPressure;
  try {
    FluidSolver fluid(mesh, o);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("'left' and 'right' (fluid.regions) lie in one region"), std::string::npos)
        << e.what();
  }
}
