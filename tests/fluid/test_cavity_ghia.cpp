// Lid-driven cavity at Re = 100 against Ghia, Ghia & Shin (1982): u on the vertical centreline and
// v on the horizontal centreline at Ghia's 17 points each. Unit square, lid u = 1, one cell thick
// in z with empty front/back, steady SIMPLE iterations.
//
// The tests run N = 32, 64 and 128. For other sizes set MFSI_GHIA_N (e.g. 64 or 128) and run
//   MFSI_GHIA_N=128 ./tests/mfsi_fluid_test_cavity_ghia --gtest_filter='*Report*'
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/GhiaTable.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

std::vector<GhiaPoint> readGhia() {
  std::ifstream in(std::string(MFSI_TEST_DATA_DIR) + "/ghia1982_re100.csv");
  std::vector<GhiaPoint> pts;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("Re", 0) == 0) continue;
    std::stringstream ss(line);
    std::string re, kind, c, v;
    std::getline(ss, re, ',');
    std::getline(ss, kind, ',');
    std::getline(ss, c, ',');
    std::getline(ss, v, ',');
    pts.push_back({kind == "u_vs_y", std::stod(c), std::stod(v)});
  }
  return pts;
}

struct CavityResult {
  double maxErrU = 0, maxErrV = 0;
  double maxErrULinear = 0, maxErrVLinear = 0;  ///< the same with linear interpolation
  int iterations = 0;
  bool converged = false;
};

CavityResult runCavity(int N, ConvectionScheme scheme = ConvectionScheme::Linear,
                        ReductionMode mode = ReductionMode::Gather) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1.0 / N}, {N, N, 1});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "frontBack", "frontBack"};
  spec.patchKinds = {{"walls", PatchKind::Wall}, {"lid", PatchKind::Wall}, {"frontBack", PatchKind::Empty}};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));

  FluidOptions o;
  o.density = 1.0;
  o.viscosity = 0.01;  // Re = U L / nu = 100
  o.timeScheme = TimeScheme::Steady;
  o.convection = scheme;
  o.reduction = mode;
  o.pimple.nOuterCorrectors = 3000;
  o.pimple.nCorrectors = 1;
  o.pimple.relaxVelocity = 0.9;
  o.pimple.relaxPressure = 0.2;
  o.pimple.outerTolerance = 1e-7;
  o.momentumSolver = {1e-9, 0.01, 200};
  o.pressureSolver = {1e-9, 0.01, 2000};
  PatchBC lid;
  lid.type = BoundaryType::Wall;
  lid.velocity = {1, 0, 0};
  o.boundaries["lid"] = lid;
  FluidSolver fluid(mesh, o);
  auto r = fluid.solveStep(0.0, 1.0);

  CavityResult out;
  out.iterations = r.outerIterations;
  out.converged = r.converged && r.ok;

  // The library comparison the cavity scene reports (fluid/GhiaTable), against the published table.
  const GhiaErrors e = ghiaErrors(fluid, 100, 1.0);
  out.maxErrU = e.uMax;
  out.maxErrV = e.vMax;
  out.maxErrULinear = e.uMaxLinear;
  out.maxErrVLinear = e.vMaxLinear;
  return out;
}

}  // namespace

TEST(CavityGhia, Re100AtN32MatchesGhiaCentrelines) {
  // The compiled-in table is Ghia's, as transcribed independently in tests/data.
  const auto csv = readGhia();
  const auto& table = ghiaTable(100);
  ASSERT_EQ(csv.size(), 34u);
  ASSERT_EQ(table.size(), csv.size());
  for (std::size_t k = 0; k < csv.size(); ++k) {
    EXPECT_EQ(table[k].uLine, csv[k].uLine) << k;
    EXPECT_EQ(table[k].coord, csv[k].coord) << k;
    EXPECT_EQ(table[k].value, csv[k].value) << k;
  }
  const auto r = runCavity(32);
  std::printf("cavity N=32: max |u - ghia| = %.5f, max |v - ghia| = %.5f, SIMPLE iterations %d\n", r.maxErrU,
              r.maxErrV, r.iterations);
  EXPECT_TRUE(r.converged);
  // Measured 0.0035 / 0.0097 at N = 32 (0.0033 / 0.0094 at 64, 0.0046 / 0.0093 at 128, where
  // Ghia's own error dominates). Upwind convection already misses by 2.5x at N = 16 (next test).
  EXPECT_LT(r.maxErrU, 0.006);
  EXPECT_LT(r.maxErrV, 0.014);
}

TEST(CavityGhia, Re100AtN64AndN128MatchGhiaCentrelines) {
  // The sizes the fluid issue asks for. Measured 0.0034 / 0.0093 (N = 64, ~1 s) and 0.0046 / 0.0093
  // (N = 128, ~9 s); OpenFOAM icoFoam on this machine: 0.0034 / 0.0087 and 0.0048 / 0.0091.
  for (int n : {64, 128}) {
    const auto r = runCavity(n);
    std::printf("cavity N=%d: max |u - ghia| = %.5f, max |v - ghia| = %.5f, SIMPLE iterations %d\n", n, r.maxErrU,
                r.maxErrV, r.iterations);
    EXPECT_TRUE(r.converged) << "N = " << n;
    EXPECT_LT(r.maxErrU, 0.0055) << "N = " << n;
    EXPECT_LT(r.maxErrV, 0.0105) << "N = " << n;
  }
}

TEST(CavityGhia, ConvectionSchemesRankAsExpectedAtN16) {
  const auto lin = runCavity(16, ConvectionScheme::Linear);
  const auto up = runCavity(16, ConvectionScheme::Upwind);
  const auto ll = runCavity(16, ConvectionScheme::LimitedLinear);
  const auto vl = runCavity(16, ConvectionScheme::VanLeer);
  auto err = [](const CavityResult& r) { return std::max(r.maxErrU, r.maxErrV); };
  std::printf("cavity N=16 max error: linear %.4f upwind %.4f limitedLinear %.4f vanLeer %.4f\n", err(lin), err(up),
              err(ll), err(vl));
  for (const auto* r : {&lin, &up, &ll, &vl}) EXPECT_TRUE(r->converged);
  EXPECT_GT(err(up), 2.0 * err(lin));
  EXPECT_LT(err(ll), 0.75 * err(up));
  EXPECT_LT(err(vl), 0.75 * err(up));
}

TEST(CavityGhia, ScatterReductionGivesTheSameSolution) {
  const auto g = runCavity(12, ConvectionScheme::Linear, ReductionMode::Gather);
  const auto s = runCavity(12, ConvectionScheme::Linear, ReductionMode::Scatter);
  EXPECT_TRUE(g.converged && s.converged);
  EXPECT_NEAR(g.maxErrU, s.maxErrU, 1e-6);
  EXPECT_NEAR(g.maxErrV, s.maxErrV, 1e-6);
}

TEST(CavityGhia, Report) {
  const char* env = std::getenv("MFSI_GHIA_N");
  if (!env) GTEST_SKIP() << "set MFSI_GHIA_N to run the convergence report";
  const int N = std::atoi(env);
  const auto r = runCavity(N);
  std::printf("cavity N=%d: max |u - ghia| = %.5f, max |v - ghia| = %.5f, SIMPLE iterations %d converged %d\n", N,
              r.maxErrU, r.maxErrV, r.iterations, int(r.converged));
  std::printf("cavity N=%d, linear interpolation: max |u - ghia| = %.5f, max |v - ghia| = %.5f\n", N, r.maxErrULinear,
              r.maxErrVLinear);
}
