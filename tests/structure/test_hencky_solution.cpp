// Hencky's exact solution (structure/membrane/HenckySolution): the series summed to round-off
// reproduces Chien's corrected table (tests/data/hencky_coefficients.csv, about 4 digits) at every
// tabulated nu, and gives the values between them that a linear interpolation of the table misses.
#include "structure/membrane/HenckySolution.hpp"
#include "core/Error.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

TEST(HenckySolution, ReproducesChiensTable) {
  std::ifstream in(std::string(MFSI_TEST_DATA_DIR) + "/hencky_coefficients.csv");
  ASSERT_TRUE(in.good());
  int rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("nu", 0) == 0) continue;
    std::stringstream ls(line);
    double nu = 0, b0 = 0, cw = 0;
    char c1 = 0, c2 = 0;
    ls >> nu >> c1 >> b0 >> c2 >> cw;
    const mfsi::HenckySolution h = mfsi::henckySolution(nu);
    // The table holds "about 4 digits": it differs from the summed series by up to 8e-5 (C_w at
    // nu = 0: 0.71832 against 0.7184) and 6e-5 (b0 at nu = 0: 1.62041 against 1.62035).
    EXPECT_NEAR(h.deflection, cw, 1e-4) << "nu = " << nu;
    EXPECT_NEAR(h.b0(), b0, 1e-4) << "nu = " << nu;
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(HenckySolution, BetweenTheTableRows) {
  // nu = 0.45: 0.611171 (the series and Föppl–Hencky integration), where interpolating
  // Chien's rows 0.4 and 0.5 gives 0.6106 (an error of 9e-4 that a 16 x 16 disc's error hides in).
  EXPECT_NEAR(mfsi::henckySolution(0.45).deflection, 0.6111706, 2e-7);
  const double interpolated = 0.5 * (0.6263 + 0.5949);
  EXPECT_GT(mfsi::henckySolution(0.45).deflection - interpolated, 5e-4);
  // Monotone in nu across the range.
  double last = 1;
  for (double nu = -0.5; nu <= 0.5; nu += 0.05) {
    const double c = mfsi::henckySolution(nu).deflection;
    EXPECT_LT(c, last) << nu;
    last = c;
  }
}

TEST(HenckySolution, RefusesPoissonRatiosOutsideTheRange) {
  EXPECT_THROW(mfsi::henckySolution(0.6), mfsi::InputError);
  EXPECT_THROW(mfsi::henckySolution(-1.0), mfsi::InputError);
}
