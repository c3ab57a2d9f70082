// Running means (fluid/RunningMean.hpp) with prescribed fields: the mean of a sampled periodic
// signal over whole periods is its offset, to round-off; with uneven steps it is the dt-weighted
// average; the first step that enters sets the mean to the field exactly, and steps ending before
// the start time do not enter.
#include "fluid/RunningMean.hpp"
#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr lid_t kCells = 7;

/// Per cell c: U_k = B(c, k) + A(c, k) sin(2 pi t / T + phase(c)), p = B_p(c) + A_p(c) cos(...).
struct Signal {
  double period = 0.8;
  double offset(lid_t c, int k) const { return 0.3 * c - 1.0 + 0.5 * k; }  // k = 3: pressure
  double amplitude(lid_t c, int k) const { return 2.0 + 0.25 * c + k; }
  double phase(lid_t c) const { return 0.4 * c; }
  double value(lid_t c, int k, double t) const {
    const double a = 2 * kPi * t / period + phase(c);
    return offset(c, k) + amplitude(c, k) * (k < 3 ? std::sin(a) : std::cos(a));
  }
};

/// The signal at time t as device fields.
void fill(const Signal& s, double t, const Real3View& U, const RealView& p) {
  auto hU = Kokkos::create_mirror_view(U);
  auto hp = Kokkos::create_mirror_view(p);
  for (lid_t c = 0; c < kCells; ++c) {
    for (int k = 0; k < 3; ++k) hU(c, k) = s.value(c, k, t);
    hp(c) = s.value(c, 3, t);
  }
  Kokkos::deep_copy(U, hU);
  Kokkos::deep_copy(p, hp);
}

}  // namespace

// N equal steps over whole periods: sum_i sin(2 pi i / N + phi) = 0 exactly, so the mean is the
// offset; the recursion's round-off over 2 x 40 steps stays below 1e-13 of the amplitude.
TEST(RunningMean, ThePeriodicSignalsMeanIsItsOffset) {
  const Signal s;
  const int perPeriod = 40;
  const double dt = s.period / perPeriod;
  RunningMean mean(kCells, {true, 0.0});
  Real3View U("test::U", kCells);
  RealView p("test::p", kCells);
  for (int i = 1; i <= 2 * perPeriod; ++i) {
    fill(s, i * dt, U, p);
    EXPECT_TRUE(mean.accumulate(ExecSpace(), i * dt, dt, U, p));
  }
  EXPECT_TRUE(near(mean.averagedTime(), 2 * s.period, Tol{0, 1e-14}));
  auto hU = Kokkos::create_mirror_view_and_copy(HostSpace(), mean.velocity());
  auto hp = Kokkos::create_mirror_view_and_copy(HostSpace(), mean.pressure());
  for (lid_t c = 0; c < kCells; ++c) {
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(near(hU(c, k), s.offset(c, k), Tol{1e-13 * s.amplitude(c, k), 0}, "UMean")) << c << " " << k;
    EXPECT_TRUE(near(hp(c), s.offset(c, 3), Tol{1e-13 * s.amplitude(c, 3), 0}, "pMean")) << c;
  }
}

// Uneven steps from start = 0.25 on: steps ending before 0.25 stay out; the first one in sets the
// mean to its field bitwise; then mean = sum dt_i f_i / sum dt_i (OpenFOAM's fieldAverage).
TEST(RunningMean, UnevenStepsGiveTheDtWeightedAverageFromTheStartOn) {
  const Signal s;
  const std::vector<double> steps = {0.1, 0.1, 0.05, 0.2, 0.013, 0.3, 0.07, 0.11};  // ends 0.1, 0.2, 0.25, ...
  RunningMean mean(kCells, {true, 0.25});
  Real3View U("test::U", kCells);
  RealView p("test::p", kCells);
  std::vector<double> weighted(4 * kCells, 0.0);
  double t = 0, total = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    t += steps[i];
    fill(s, t, U, p);
    const bool in = mean.accumulate(ExecSpace(), t, steps[i], U, p);
    EXPECT_EQ(in, i >= 2) << "step " << i << " ending at " << t;
    if (!in) continue;
    total += steps[i];
    for (lid_t c = 0; c < kCells; ++c)
      for (int k = 0; k < 4; ++k) weighted[4 * c + k] += steps[i] * s.value(c, k, t);
    if (i == 2) {
      auto hU = Kokkos::create_mirror_view_and_copy(HostSpace(), mean.velocity());
      auto fU = Kokkos::create_mirror_view_and_copy(HostSpace(), U);
      for (lid_t c = 0; c < kCells; ++c)
        for (int k = 0; k < 3; ++k) EXPECT_EQ(hU(c, k), fU(c, k)) << "the first mean is the field";
    }
  }
  EXPECT_TRUE(near(mean.averagedTime(), total, Tol{0, 1e-15}));
  auto hU = Kokkos::create_mirror_view_and_copy(HostSpace(), mean.velocity());
  auto hp = Kokkos::create_mirror_view_and_copy(HostSpace(), mean.pressure());
  for (lid_t c = 0; c < kCells; ++c) {
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(hU(c, k), weighted[4 * c + k] / total, Tol{1e-14, 1e-13}, "UMean"));
    EXPECT_TRUE(near(hp(c), weighted[4 * c + 3] / total, Tol{1e-14, 1e-13}, "pMean"));
  }
}
