// The k-d tree's nearest squared distance is the brute-force minimum, bit for bit: points on a
// bumpy surface (a membrane's nodes) and scattered in a box, queries inside and far outside,
// duplicate points, and an empty tree.
#include "core/PointTree.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using mfsi::PointTree;
using mfsi::real;
using P = std::array<real, 3>;

namespace {

real bruteForce(const std::vector<P>& pts, const P& x) {
  real best = std::numeric_limits<real>::infinity();
  for (const P& p : pts) {
    const real dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
    best = std::min(best, dx * dx + dy * dy + dz * dz);
  }
  return best;
}

}  // namespace

TEST(PointTree, NearestIsTheBruteForceMinimum) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<real> u(-1, 1);
  std::vector<P> pts;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const real x = i / 39.0, y = j / 39.0;
      pts.push_back({x, y, 0.1 * std::sin(6 * x) * std::cos(4 * y)});  // a bumpy surface
    }
  for (int i = 0; i < 300; ++i) pts.push_back({u(gen), u(gen), u(gen)});
  pts.push_back(pts[5]);  // a duplicate
  const PointTree tree(pts);
  EXPECT_EQ(tree.size(), pts.size());
  for (int q = 0; q < 3000; ++q) {
    const real s = q < 2000 ? 1.0 : 20.0;  // inside, then far outside
    const P x{s * u(gen), s * u(gen), s * u(gen)};
    ASSERT_EQ(tree.nearestSquaredDistance(x), bruteForce(pts, x)) << "query " << q;
  }
  EXPECT_EQ(tree.nearestSquaredDistance(pts[17]), 0.0);
}

TEST(PointTree, EmptyAndSinglePoint) {
  EXPECT_EQ(PointTree({}).nearestSquaredDistance({0, 0, 0}), std::numeric_limits<real>::infinity());
  EXPECT_EQ(PointTree({{1, 2, 3}}).nearestSquaredDistance({1, 2, 5}), 4.0);
}
