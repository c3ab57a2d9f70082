// Rotation-free plate bending of the membrane (structure/membrane/MembraneBending.hpp):
//  - the hinge angle's gradient against central differences, and its invariance under rigid motions;
//  - the energy's calibration: a strip rolled into a half cylinder stores exactly D/2 k^2 per area of
//    its interior strips (large rotation); a small saddle and a small sphere store the nu = 0 plate
//    energy D/2 (k11^2 + k22^2 + 2 k12^2) of the hinges they span;
//  - a simply supported square plate under uniform pressure: the centre deflection converges to
//    Navier's series w = 16 q a^4 / (pi^6 D) sum_{m,n odd} (-1)^((m+n)/2-1) / (m n (m^2+n^2)^2);
//  - its natural frequencies (tangent and consistent mass, no pre-stress: bending alone holds it)
//    against omega_mn = pi^2 ((m/a)^2 + (n/a)^2) sqrt(D / (rho h)).
#include "support/Approx.hpp"
#include "support/DenseCsr.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>

using namespace mfsi;
using mfsi::test::dense;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

const double kPi = std::acos(-1.0);

MembraneMesh rectangle(double lx, double ly, int nx, int ny) {
  MembraneRectangleSpec r;
  r.lx = lx;
  r.ly = ly;
  r.nx = nx;
  r.ny = ny;
  return buildMembraneMesh(generateRectangleMesh(r));
}

/// Device displacement from a host function of the reference point.
template <class F>
RealView displacementOf(const MembraneMesh& mesh, const F& f) {
  RealView u("u", 3 * mesh.nNodes());
  auto h = Kokkos::create_mirror_view(u);
  for (lid_t n = 0; n < mesh.nNodes(); ++n) {
    const std::array<double, 3> d = f(mesh.hostPoints()[n]);
    for (int k = 0; k < 3; ++k) h(3 * n + k) = d[k];
  }
  Kokkos::deep_copy(u, h);
  return u;
}

double energy(const MembraneMesh& mesh, const MembraneHinges& hinges, const RealView& u) {
  return membraneBendingEnergy(ExecSpace(), hinges, mesh.referencePoints(), u);
}

}  // namespace

TEST(MembraneBending, HingeGradientMatchesDifferences) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    double x[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.4, 1, 0}, {0.6, -1, 0}};
    for (auto& p : x)
      for (double& c : p) c += jitter(gen);
    double theta = 0, g[4][3];
    ASSERT_TRUE(membrane::hingeAngle(x, theta, g));
    const double h = 1e-6;
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) {
        double xp[4][3], xm[4][3], tp = 0, tm = 0, gd[4][3];
        std::copy(&x[0][0], &x[0][0] + 12, &xp[0][0]);
        std::copy(&x[0][0], &x[0][0] + 12, &xm[0][0]);
        xp[a][k] += h;
        xm[a][k] -= h;
        membrane::hingeAngle(xp, tp, gd);
        membrane::hingeAngle(xm, tm, gd);
        EXPECT_TRUE(near(g[a][k], (tp - tm) / (2 * h), Tol{1e-7, 1e-6}, "trial " + std::to_string(trial)));
      }
  }
  // Both wings raised: the hinge folds by the sum of their tilts.
  const double d = 1e-3;
  double x[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, d}, {0.5, -1, d}}, theta = 0, g[4][3];
  ASSERT_TRUE(membrane::hingeAngle(x, theta, g));
  EXPECT_TRUE(near(std::abs(theta), 2 * std::atan(d), Tol{0, 1e-9}));
}

TEST(MembraneBending, RigidMotionsStoreNoEnergy) {
  // A curved reference (a dome) moved rigidly: zero energy, zero residual.
  MembraneRectangleSpec r;
  r.nx = r.ny = 6;
  MembraneMeshInput in = generateRectangleMesh(r);
  for (auto& p : in.points) p[2] = 0.2 * std::sin(kPi * p[0]) * std::sin(kPi * p[1]);
  const MembraneMesh dome = buildMembraneMesh(in);
  const MembraneHinges hinges = buildMembraneHinges(dome, 1.0);
  const double c = std::cos(1.1), s = std::sin(1.1);
  const RealView u = displacementOf(dome, [&](const std::array<double, 3>& X) {
    const std::array<double, 3> y = {c * X[0] - s * X[2] + 0.3, X[1] - 2.0, s * X[0] + c * X[2] + 0.7};
    return std::array<double, 3>{y[0] - X[0], y[1] - X[1], y[2] - X[2]};
  });
  EXPECT_TRUE(near(energy(dome, hinges, u), 0, Tol{1e-24, 0}));
  ItemValuesView res("res", hinges.size(), 12), ext("ext", hinges.size(), 12);
  membraneHingeResidualItems(ExecSpace(), hinges, dome.referencePoints(), u, 0, res, ext);
  auto hr = Kokkos::create_mirror_view_and_copy(HostSpace(), res);
  double worst = 0;
  for (lid_t i = 0; i < hinges.size(); ++i)
    for (int k = 0; k < 12; ++k) worst = std::max(worst, std::abs(hr(i, k)));
  EXPECT_LT(worst, 1e-12);
}

TEST(MembraneBending, RolledStripStoresThePlateEnergy) {
  // A 1 x 0.25 strip (16 x 4 cells) rolled about the y axis into half a cylinder of radius 1/pi:
  // every vertical interior edge folds by a / R exactly, the cells stay flat, so the energy is
  // D/2 k^2 over the (nx - 1) interior strips of width a, to round-off, at any rotation.
  const int nx = 16, ny = 4;
  const double lx = 1, ly = 0.25, a = lx / nx, R = 1 / kPi, D = 2.5;
  const MembraneMesh mesh = rectangle(lx, ly, nx, ny);
  const MembraneHinges hinges = buildMembraneHinges(mesh, D);
  EXPECT_EQ(hinges.size(), 2 * ((nx - 1) * ny + nx * (ny - 1)) + 2 * nx * ny);
  const RealView u = displacementOf(mesh, [&](const std::array<double, 3>& X) {
    return std::array<double, 3>{R * std::sin(X[0] / R) - X[0], 0.0, R * (1 - std::cos(X[0] / R))};
  });
  EXPECT_TRUE(near(energy(mesh, hinges, u), 0.5 * D / (R * R) * (lx - a) * ly, Tol{0, 1e-12}));
}

TEST(MembraneBending, SmallCurvaturesGiveTheNuZeroPlateEnergy) {
  // w = (k11 x^2 + 2 k12 x y + k22 y^2) / 2 on a square grid of spacing a: each interior vertical
  // edge stores D/2 a^2 k11^2, each horizontal one D/2 a^2 k22^2, each cell's diagonals D a^2 k12^2
  // (so D/2 (k11^2 + k22^2 + 2 k12^2) per cell inside); small deflection, so to O(slope^2).
  const int n = 8;
  const double a = 1.0 / n, D = 1.0;
  const MembraneMesh mesh = rectangle(1, 1, n, n);
  const MembraneHinges hinges = buildMembraneHinges(mesh, D);
  const double nEdges = (n - 1) * n, nCells = n * n;
  struct Shape {
    const char* name;
    double k11, k12, k22;
  };
  for (const Shape& sh : {Shape{"cylinder", 1e-3, 0, 0}, Shape{"saddle", 0, 1e-3, 0}, Shape{"sphere", 1e-3, 0, 1e-3},
                          Shape{"mixed", 1e-3, -4e-4, 2e-3}}) {
    const RealView u = displacementOf(mesh, [&](const std::array<double, 3>& X) {
      const double x = X[0] - 0.5, y = X[1] - 0.5;
      return std::array<double, 3>{0.0, 0.0, 0.5 * (sh.k11 * x * x + 2 * sh.k12 * x * y + sh.k22 * y * y)};
    });
    const double expected =
        0.5 * D * a * a *
        (nEdges * (sh.k11 * sh.k11 + sh.k22 * sh.k22) + 2 * nCells * sh.k12 * sh.k12);
    EXPECT_TRUE(near(energy(mesh, hinges, u), expected, Tol{0, 1e-5}, sh.name));
  }
}

TEST(MembraneBending, SimplySupportedPlateMatchesNavier) {
  // Square plate a = 1, E = 1e6 (nu = 0.3), h = 0.01: D = E h^3 / (12 (1 - nu^2)). Uniform q small
  // enough that the centre deflection is 0.2 % of h (membrane action, ~(w/h)^2, negligible). Rim pinned: no
  // hinge there, so no moment (simply supported).
  double series = 0;
  for (int m = 1; m < 400; m += 2)
    for (int k = 1; k < 400; k += 2)
      series += (((m + k) / 2 - 1) % 2 == 0 ? 1.0 : -1.0) / (m * k * std::pow(m * m + k * k, 2));
  MembraneOptions opt;
  opt.material = {1e6, 0.3, 0.01, 0, 0};
  opt.material.bending = true;
  opt.tolerance = 1e-10;
  const double D = plateBendingStiffness(opt.material), q = 0.002 * 0.01 * D / (0.00406 * 1.0);
  const double navier = 16 * q / (std::pow(kPi, 6) * D) * series;
  EXPECT_TRUE(near(navier / (q / D), 0.00406, Tol{0, 1e-3}));  // Timoshenko's table value
  std::vector<double> err;
  for (int n : {8, 16}) {
    const MembraneMesh mesh = rectangle(1, 1, n, n);
    MembraneBoundary bc;
    bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
    MembraneLoads loads;
    loads.pressure = q;
    MembraneSolver s(mesh, opt, bc, loads);
    const auto rep = s.solveStatic();
    ASSERT_TRUE(rep.converged) << n;
    const double w = s.summary().at("centreDeflection");
    err.push_back(std::abs(w - navier) / navier);
    EXPECT_GT(s.summary().at("bendingEnergy"), 0);
  }
  // Measured: 1.9e-3 (8 x 8), 4.9e-4 (16 x 16), 1.5e-4 (32 x 32).
  EXPECT_LT(err[1], 1e-3) << "16 x 16: " << err[1];
  EXPECT_LT(err[1], 0.3 * err[0]) << "second order: 8 x 8 " << err[0] << ", 16 x 16 " << err[1];
}

TEST(MembraneBending, SimplySupportedPlateFrequencies) {
  const int n = 16;
  const double a = 1, rho = 1000;
  const MembraneMesh mesh = rectangle(a, a, n, n);
  MembraneOptions opt;
  opt.material = {1e6, 0.3, 0.01, rho, 0};
  opt.material.bending = true;
  opt.newton.tangentStressFloor = 0;  // the flat, unstressed membrane adds nothing out of plane
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneSolver s(mesh, opt, bc);
  const Eigen::MatrixXd K = dense(s.assembleTangent(0.0));
  const Eigen::MatrixXd M = dense(s.assembleConsistentMass());
  const auto& boundary = mesh.boundaryNodes();
  std::vector<int> z;
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    if (!std::binary_search(boundary.begin(), boundary.end(), i)) z.push_back(3 * i + 2);
  const int nz = static_cast<int>(z.size());
  Eigen::MatrixXd Kz(nz, nz), Mz(nz, nz);
  for (int i = 0; i < nz; ++i)
    for (int j = 0; j < nz; ++j) {
      Kz(i, j) = K(z[i], z[j]);
      Mz(i, j) = M(z[i], z[j]);
    }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kz, Mz);
  ASSERT_EQ(eig.info(), Eigen::Success);
  const double D = plateBendingStiffness(opt.material), h = opt.material.thickness;
  const int modes[4][2] = {{1, 1}, {1, 2}, {2, 1}, {2, 2}};
  for (int k = 0; k < 4; ++k) {
    const double exact =
        kPi * kPi * (std::pow(modes[k][0] / a, 2) + std::pow(modes[k][1] / a, 2)) * std::sqrt(D / (rho * h));
    const double omega = std::sqrt(eig.eigenvalues()(k));
    // Measured at 16 x 16: +0.32 %, +0.52 %, +0.52 %, +1.29 % (the (2, 2) mode has 4 cells per half-wave).
    std::printf("mode %d: omega %.5f exact %.5f rel %.2e\n", k, omega, exact, omega / exact - 1);
    EXPECT_TRUE(near(omega, exact, Tol{0, k < 3 ? 0.007 : 0.015}, "mode " + std::to_string(k)));
  }
}

TEST(MembraneBending, TrianglesAreRefused) {
  MembraneRectangleSpec r;
  r.type = MembraneElementType::Tri3;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(r));
  EXPECT_THROW(buildMembraneHinges(mesh, 1.0), InputError);
}
