// Closed chambers that share membranes (coupling/chambers/ChamberGroup): grouping by shared walls
// and the two linear solves of the volume split, against hand-derived values.
//  - Chambers join a group through any chain of shared walls; each group's incidence carries the
//    walls' signs, and a group bounded only by the membranes between its chambers is told apart.
//  - shareOut: E s = d, with the least weighted s (worked out by hand below).
//  - agreedMultipliers: walls that carry E^T Lambda return Lambda; otherwise the compliance-
//    weighted least-squares fit (by hand below).
#include "coupling/chambers/ChamberGroup.hpp"

#include "support/Approx.hpp"

#include <gtest/gtest.h>

using mfsi::coupling::agreedMultipliers;
using mfsi::coupling::ChamberGroup;
using mfsi::coupling::groupChambers;
using mfsi::coupling::shareOut;
using mfsi::test::allNear;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

using Walls = std::vector<std::vector<std::pair<int, double>>>;

/// Two chambers A (walls 0, 1) and B (walls 1 seen from the other side, 2): E = [[1, 1, 0], [0, -1, 1]].
ChamberGroup twoChambersThreeWalls() {
  const std::vector<ChamberGroup> g = groupChambers(Walls{{{0, 1.0}, {1, 1.0}}, {{1, -1.0}, {2, 1.0}}});
  EXPECT_EQ(g.size(), 1u);
  return g.front();
}

}  // namespace

TEST(ChamberGroup, ChambersJoinThroughSharedWallsWithTheirSigns) {
  // 0 alone; 1 and 2 share panel 2; 3 alone; listed so that the flood meets panels out of order.
  const Walls walls{{{0, 1.0}}, {{1, 1.0}, {2, 1.0}}, {{2, -1.0}, {3, 1.0}}, {{4, 1.0}}};
  const std::vector<ChamberGroup> g = groupChambers(walls);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[0].chambers, std::vector<int>{0});
  EXPECT_EQ(g[1].chambers, (std::vector<int>{1, 2}));
  EXPECT_EQ(g[1].panels, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(g[2].chambers, std::vector<int>{3});
  Eigen::MatrixXd E(2, 3);
  E << 1, 1, 0, 0, -1, 1;
  EXPECT_EQ(g[1].incidence, E);
  EXPECT_EQ(g[1].column(3), 2);
  EXPECT_EQ(g[1].column(0), -1);
  for (const ChamberGroup& x : g) EXPECT_TRUE(x.pressuresFixed());
}

TEST(ChamberGroup, AChainOfSharedWallsIsOneGroup) {
  // A - B through panel 1, B - C through panel 2: A and C share nothing but are one group.
  const std::vector<ChamberGroup> g =
      groupChambers(Walls{{{0, 1.0}, {1, 1.0}}, {{1, -1.0}, {2, 1.0}}, {{2, -1.0}, {3, 1.0}}});
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].chambers, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(g[0].panels.size(), 4u);
  EXPECT_TRUE(g[0].pressuresFixed());
}

TEST(ChamberGroup, ChambersBoundedOnlyByTheMembraneBetweenThemAreNotFixed) {
  // One membrane between two closed chambers and no other wall: E = [[1], [-1]], rank 1.
  const std::vector<ChamberGroup> g = groupChambers(Walls{{{0, 1.0}}, {{0, -1.0}}});
  ASSERT_EQ(g.size(), 1u);
  EXPECT_FALSE(g[0].pressuresFixed());
  // Nested: A under the membrane 0, B above it closed by membrane 1: E = [[1, 0], [-1, 1]].
  const std::vector<ChamberGroup> nested = groupChambers(Walls{{{0, 1.0}}, {{0, -1.0}, {1, 1.0}}});
  ASSERT_EQ(nested.size(), 1u);
  EXPECT_TRUE(nested[0].pressuresFixed());
}

TEST(ChamberGroup, ShareOutMeetsTheChambersVolumesWithTheLeastWeightedShares) {
  // One chamber: in proportion to the weights.
  const ChamberGroup one = groupChambers(Walls{{{0, 1.0}, {1, 1.0}}}).front();
  const Eigen::VectorXd s1 = shareOut(one, Eigen::Vector2d(1, 3), Eigen::VectorXd::Constant(1, 4.0));
  EXPECT_TRUE(allNear(s1, Eigen::Vector2d(1, 3), 2, Tol{1e-15, 0}, "one chamber"));
  // Nested (E square): s = E^-1 d whatever the weights: the lower wall takes A's volume, the
  // upper one A's and B's.
  const ChamberGroup nested = groupChambers(Walls{{{0, 1.0}}, {{0, -1.0}, {1, 1.0}}}).front();
  const Eigen::VectorXd s2 = shareOut(nested, Eigen::Vector2d(2, 7), Eigen::Vector2d(0.004, 0.002));
  EXPECT_TRUE(allNear(s2, Eigen::Vector2d(0.004, 0.006), 2, Tol{1e-17, 1e-14}, "nested"));
  // E = [[1, 1, 0], [0, -1, 1]], W = I, d = (1, 0): E E^T = [[2, -1], [-1, 2]], y = (2/3, 1/3),
  // s = E^T y = (2/3, 1/3, 1/3).
  const ChamberGroup g = twoChambersThreeWalls();
  const Eigen::VectorXd s3 = shareOut(g, Eigen::Vector3d(1, 1, 1), Eigen::Vector2d(1, 0));
  EXPECT_TRUE(allNear(s3, Eigen::Vector3d(2.0 / 3, 1.0 / 3, 1.0 / 3), 3, Tol{1e-15, 0}, "E W E^T"));
  // Unequal weights still meet the chambers' volumes exactly.
  const Eigen::Vector2d d(0.3, -0.1);
  const Eigen::VectorXd s4 = shareOut(g, Eigen::Vector3d(0.5, 2, 1), d);
  const Eigen::VectorXd met = g.incidence * s4;
  EXPECT_TRUE(allNear(met, d, 2, Tol{1e-15, 0}, "E s"));
}

TEST(ChamberGroup, AgreedMultipliersFitTheWallsByCompliance) {
  // One chamber: the compliance-weighted mean.
  const ChamberGroup one = groupChambers(Walls{{{0, 1.0}, {1, 1.0}}}).front();
  EXPECT_TRUE(near(agreedMultipliers(one, Eigen::Vector2d(1, 3), Eigen::Vector2d(2, 6))[0], 5.0, Tol{1e-15, 0}));
  const ChamberGroup g = twoChambersThreeWalls();
  // Walls carrying E^T Lambda (the shared wall the difference) return Lambda.
  const Eigen::VectorXd exact = agreedMultipliers(g, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(5, 3, 2));
  EXPECT_TRUE(allNear(exact, Eigen::Vector2d(5, 2), 2, Tol{1e-14, 0}, "consistent"));
  // C = I, lambda = (1, 0, 0): E C E^T = [[2, -1], [-1, 2]], E C lambda = (1, 0), Lambda = (2/3, 1/3).
  const Eigen::VectorXd fit = agreedMultipliers(g, Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE(allNear(fit, Eigen::Vector2d(2.0 / 3, 1.0 / 3), 2, Tol{1e-15, 0}, "fit"));
}
