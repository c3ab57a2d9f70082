// Hencky's problem: a clamped circular membrane (radius a, no pre-stress) under uniform pressure
// p deflects w0 = C a (p a / (E h))^(1/3) at its centre; C = 0.6535 for nu = 0.3, 0.7184 for
// nu = 0, 0.5949 for nu = 0.5 (exact series of Hencky 1915 as corrected by Chien 1948;
// tests/data/hencky_coefficients.csv). The theory is the Foppl membrane with a load along the
// initial normal; at p a/(E h) = 1e-5 the centre slope terms it neglects are ~ 1e-4 relative.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

using namespace mfsi;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

/// Hencky coefficient C_w(nu) from the reference table copied into tests/data.
double henckyCoefficient(double nu) {
  std::ifstream in(std::string(MFSI_TEST_DATA_DIR) + "/hencky_coefficients.csv");
  EXPECT_TRUE(in.good()) << "missing tests/data/hencky_coefficients.csv";
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'n') continue;
    std::istringstream ls(line);
    double v, b0, cw;
    char c1, c2;
    if (ls >> v >> c1 >> b0 >> c2 >> cw && std::abs(v - nu) < 1e-12) return cw;
  }
  ADD_FAILURE() << "no Hencky coefficient for nu = " << nu;
  return 0;
}

struct HenckyRun {
  double w0 = 0;
  MembraneSolveReport report;
};

HenckyRun solveHencky(int nCore, int nRing, double nu, double load, MembraneStaticSolver solver, double tol,
                      MembranePressureDirection dir = MembranePressureDirection::Follower) {
  MembraneDiscSpec disc;
  disc.radius = 1.0;
  disc.nCore = nCore;
  disc.nRing = nRing;
  const MembraneMesh mesh = buildMembraneMesh(generateDiscMesh(disc));
  MembraneOptions opt;
  opt.material.youngsModulus = 1e9;
  opt.material.poissonRatio = nu;
  opt.material.thickness = 1e-3;
  opt.solver = solver;
  opt.tolerance = tol;
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneLoads loads;
  loads.pressure = load * 1e9 * 1e-3 / disc.radius;  // p a / (E h) = load
  loads.direction = dir;
  MembraneSolver s(mesh, opt, bc, loads);
  HenckyRun run;
  run.report = s.solveStatic();
  run.w0 = s.summary().at("centreDeflection");
  return run;
}

}  // namespace

TEST(MembraneHencky, ConvergesToExactCentreDeflection) {
  const double load = 1e-5;
  const double exact = henckyCoefficient(0.3) * std::cbrt(load);
  double previous = 1e300;
  const int sizes[3][2] = {{4, 4}, {8, 8}, {16, 16}};
  for (const auto& n : sizes) {
    const HenckyRun r = solveHencky(n[0], n[1], 0.3, load, MembraneStaticSolver::Newton, 1e-8);
    ASSERT_TRUE(r.report.converged) << "mesh " << n[0] << "x" << n[1];
    const double err = std::abs(r.w0 - exact) / exact;
    std::printf("hencky mesh %2d/%2d: w0 = %.6e exact %.6e rel.err %.3e (newton %d it, %d cg)\n", n[0], n[1], r.w0,
                exact, err, r.report.iterations, r.report.linearIterations);
    EXPECT_LT(err, previous) << "error must decrease under refinement";
    previous = err;
  }
  EXPECT_LT(previous, 0.01) << "finest mesh within 1 %";
}

TEST(MembraneHencky, PoissonRatioDependence) {
  // The coefficient depends on nu; nu = 0 and 0.5 bracket the range of the table.
  const double load = 1e-5;
  for (double nu : {0.0, 0.5}) {
    const HenckyRun r = solveHencky(8, 8, nu, load, MembraneStaticSolver::Newton, 1e-8);
    ASSERT_TRUE(r.report.converged);
    EXPECT_TRUE(near(r.w0, henckyCoefficient(nu) * std::cbrt(load), Tol{0, 0.01}, "w0 at nu"));
  }
}

TEST(MembraneHencky, LumpedAndConsistentNewtonAgree) {
  const double load = 1e-5;
  const HenckyRun lumped = solveHencky(4, 4, 0.3, load, MembraneStaticSolver::LumpedNewtonRaphson, 1e-4);
  const HenckyRun newton = solveHencky(4, 4, 0.3, load, MembraneStaticSolver::Newton, 1e-4);
  std::printf("lumped NR: %d iterations w0 %.6e; Newton: %d iterations (%d CG) w0 %.6e\n", lumped.report.iterations,
              lumped.w0, newton.report.iterations, newton.report.linearIterations, newton.w0);
  ASSERT_TRUE(lumped.report.converged);
  ASSERT_TRUE(newton.report.converged);
  EXPECT_TRUE(near(lumped.w0, newton.w0, Tol{0, 2e-3}, "same Hencky answer"));
  EXPECT_LT(3 * newton.report.iterations, lumped.report.iterations);
}

TEST(MembraneHencky, FollowerAndDeadPressureAgreeAtSmallSlopes) {
  // Hencky's load is dead (along the initial normal); the follower load differs by O(slope^2)
  // ~ 1e-3 here. Both must meet the theory; they must not coincide (the option does something).
  const double load = 1e-5;
  const HenckyRun follower = solveHencky(8, 8, 0.3, load, MembraneStaticSolver::Newton, 1e-9);
  const HenckyRun dead =
      solveHencky(8, 8, 0.3, load, MembraneStaticSolver::Newton, 1e-9, MembranePressureDirection::Dead);
  ASSERT_TRUE(follower.report.converged && dead.report.converged);
  EXPECT_TRUE(near(dead.w0, follower.w0, Tol{0, 2e-3}, "dead vs follower"));
  EXPECT_GT(std::abs(dead.w0 - follower.w0), 1e-7 * follower.w0);
  EXPECT_TRUE(near(dead.w0, henckyCoefficient(0.3) * std::cbrt(load), Tol{0, 0.01}, "dead-load w0"));
}
