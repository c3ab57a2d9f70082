// Lid-driven cavity at Re = 100 against Ghia, Ghia & Shin (1982): u on the vertical centreline and
// v on the horizontal centreline at Ghia's 17 points each. Unit square, lid u = 1, one cell thick
// in z with empty front/back, steady SIMPLE iterations.
//
// The tests run N = 32, 64 and 128. For other sizes set MFSI_GHIA_N (e.g. 64 or 128) and run
//   MFSI_GHIA_N=128 ./tests/mfsi_fluid_test_cavity_ghia --gtest_filter='*Report*'
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

struct GhiaPoint {
  bool uLine;  // u on x = 0.5 vs y; else v on y = 0.5 vs x
  double coord, value;
};

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

// Cubic Lagrange interpolation through the 4 samples nearest to s.
double interp(const std::vector<double>& x, const std::vector<double>& y, double s) {
  std::size_t k = 0;
  while (k + 1 < x.size() && x[k + 1] < s) ++k;
  std::size_t i0 = k >= 1 ? k - 1 : 0;
  if (i0 + 4 > x.size()) i0 = x.size() - 4;
  double r = 0;
  for (std::size_t a = i0; a < i0 + 4; ++a) {
    double l = 1;
    for (std::size_t b = i0; b < i0 + 4; ++b)
      if (b != a) l *= (s - x[b]) / (x[a] - x[b]);
    r += l * y[a];
  }
  return r;
}

// Linear interpolation between neighbouring samples (how perf/openfoam/cavity_ghia.py samples
// OpenFOAM's fields), for like-for-like comparisons in the report.
double interpLinear(const std::vector<double>& x, const std::vector<double>& y, double s) {
  std::size_t k = 0;
  while (k + 2 < x.size() && x[k + 1] < s) ++k;
  const double w = (s - x[k]) / (x[k + 1] - x[k]);
  return (1 - w) * y[k] + w * y[k + 1];
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

  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  const double h = 1.0 / N;
  std::vector<double> uc(N * N), vc(N * N);
  for (int c = 0; c < mesh.nCells(); ++c) {
    const int i = static_cast<int>(C(c, 0) / h), j = static_cast<int>(C(c, 1) / h);
    uc[j * N + i] = U(c, 0);
    vc[j * N + i] = U(c, 1);
  }
  // Centreline profiles (average of the two cell columns/rows next to the line) plus wall values.
  std::vector<double> ys{0.0}, us{0.0}, xs{0.0}, vs{0.0};
  for (int j = 0; j < N; ++j) {
    ys.push_back((j + 0.5) * h);
    us.push_back(0.5 * (uc[j * N + N / 2 - 1] + uc[j * N + N / 2]));
    xs.push_back((j + 0.5) * h);
    vs.push_back(0.5 * (vc[(N / 2 - 1) * N + j] + vc[(N / 2) * N + j]));
  }
  ys.push_back(1.0);
  us.push_back(1.0);
  xs.push_back(1.0);
  vs.push_back(0.0);
  for (const auto& g : readGhia()) {
    const double e = g.uLine ? std::abs(interp(ys, us, g.coord) - g.value) : std::abs(interp(xs, vs, g.coord) - g.value);
    (g.uLine ? out.maxErrU : out.maxErrV) = std::max(g.uLine ? out.maxErrU : out.maxErrV, e);
    const double el = g.uLine ? std::abs(interpLinear(ys, us, g.coord) - g.value)
                              : std::abs(interpLinear(xs, vs, g.coord) - g.value);
    (g.uLine ? out.maxErrULinear : out.maxErrVLinear) =
        std::max(g.uLine ? out.maxErrULinear : out.maxErrVLinear, el);
  }
  return out;
}

}  // namespace

TEST(CavityGhia, Re100AtN32MatchesGhiaCentrelines) {
  ASSERT_EQ(readGhia().size(), 34u);
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
