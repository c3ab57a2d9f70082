// The `limited psi` face-normal gradients (FluidOptions::nonOrthogonalLimit, OpenFOAM's scheme):
// each face's explicit non-orthogonal correction is clamped to psi / (1 - psi) times its
// orthogonal part. A limit that only faces with a vanishing pressure difference reach leaves the
// corrected answer; a limit that faces do reach moves it; psi = 0 is the uncorrected scheme.
#include "fluid/FluidSolver.hpp"
#include "support/DistributedFluidCases.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

std::vector<double> cavityFields(double distortion, double limit) {
  const HexMesh mesh = buildHexMesh(test::cavityCube(6, distortion));
  FluidOptions o = test::cavityOptions(1);
  o.nonOrthogonalLimit = limit;
  FluidSolver f(mesh, o);
  for (int s = 0; s < 3; ++s) EXPECT_TRUE(f.solveStep(s * 0.05, 0.05).ok);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), f.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), f.pressure());
  std::vector<double> v;
  for (lid_t c = 0; c < mesh.nCells(); ++c) v.insert(v.end(), {U(c, 0), U(c, 1), U(c, 2), p(c)});
  return v;
}

double maxDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

TEST(NonOrthogonalLimit, AnUnreachedLimitIsTheCorrectedScheme) {
  // Interior nodes moved by 2 % of a cell: every correction is far below 1e6 times its orthogonal
  // part except where the pressure difference across a face vanishes (the uniform start), and
  // there the correction is small too. Measured 1.4e-9 (fields ~0.1 to 1).
  const auto corrected = cavityFields(0.02, 1.0);
  const auto limited = cavityFields(0.02, 0.999999);
  const auto uncorrected = cavityFields(0.02, 0.0);
  EXPECT_LT(maxDiff(corrected, limited), 1e-7);
  EXPECT_GT(maxDiff(corrected, uncorrected), 1e-5);
}

TEST(NonOrthogonalLimit, AReachedLimitMovesTheAnswerTowardsTheUncorrectedOne) {
  const auto corrected = cavityFields(0.3, 1.0);
  const auto half = cavityFields(0.3, 0.5);
  const auto tight = cavityFields(0.3, 0.05);
  const auto uncorrected = cavityFields(0.3, 0.0);
  const double full = maxDiff(corrected, uncorrected);
  std::printf("distorted cavity: |corrected - uncorrected| %.3e, limited 0.5 %.3e, limited 0.05 %.3e\n", full,
              maxDiff(corrected, half), maxDiff(corrected, tight));
  ASSERT_GT(full, 1e-4);  // the correction matters on this mesh
  EXPECT_GT(maxDiff(corrected, half), 1e-9);  // some face reaches the limit
  // The tighter the limit, the closer to the uncorrected scheme.
  EXPECT_LT(maxDiff(tight, uncorrected), maxDiff(half, uncorrected));
  EXPECT_LT(maxDiff(half, uncorrected), full);
}
