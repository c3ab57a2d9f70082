// Pre-stressed square membrane (side a, tension T0, areal density rho h), clamped edges:
// small-amplitude natural frequencies f_mn = (1/2) sqrt(T0/(rho h)) sqrt((m/a)^2 + (n/a)^2).
//  - generalized eigenvalues of the assembled tangent and consistent mass (Eigen, on the host,
//    out-of-plane dofs: at the flat pre-stressed state they decouple from the in-plane ones,
//    which the test checks);
//  - implicit time integration from a (1,1) mode shape: period from zero crossings of the centre
//    deflection (Newmark consistent and lumped mass, generalized-alpha);
//  - Rayleigh damping: logarithmic decrement against 2 pi zeta, zeta = alpha/(2 w) + beta w/2.
#include "support/Approx.hpp"
#include "support/DenseCsr.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

using namespace mfsi;
using mfsi::test::dense;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kSide = 1.0, kT0 = 100.0, kRho = 1000.0, kH = 1e-3, kE = 1e7, kNu = 0.3;
const double kPi = std::acos(-1.0);

double exactFrequency(int m, int n) {
  return 0.5 * std::sqrt(kT0 / (kRho * kH)) * std::sqrt(double(m * m + n * n)) / kSide;
}

MembraneOptions squareOptions() {
  MembraneOptions opt;
  opt.material = {kE, kNu, kH, kRho, kT0};
  opt.tolerance = 1e-9;
  return opt;
}

MembraneMesh squareMesh(int n) {
  MembraneRectangleSpec rect;
  rect.lx = rect.ly = kSide;
  rect.nx = rect.ny = n;
  return buildMembraneMesh(generateRectangleMesh(rect));
}

/// Centre-deflection history of free vibration from w = A sin(pi x) sin(pi y).
std::vector<double> vibrate(const MembraneOptions& opt, int n, int steps, double dt) {
  const MembraneMesh mesh = squareMesh(n);
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneSolver s(mesh, opt, bc);
  const double A = 1e-4;
  auto u = Kokkos::create_mirror(s.displacement());
  Kokkos::deep_copy(u, 0.0);
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    const auto& X = mesh.hostPoints()[i];
    u(3 * i + 2) = A * std::sin(kPi * X[0] / kSide) * std::sin(kPi * X[1] / kSide);
  }
  Kokkos::deep_copy(s.displacement(), u);
  s.resetDynamics();
  const lid_t c = mesh.nodeSet("centre").front();
  std::vector<double> w{A};
  for (int k = 0; k < steps; ++k) {
    const auto rep = s.step(dt);
    EXPECT_TRUE(rep.converged) << "step " << k;
    if (!rep.converged) break;
    auto uh = Kokkos::create_mirror(s.displacement());
    Kokkos::deep_copy(uh, s.displacement());
    w.push_back(uh(3 * c + 2));
  }
  return w;
}

/// Mean period from the zero crossings (linear interpolation) of a sampled signal.
double periodFromZeroCrossings(const std::vector<double>& w, double dt) {
  std::vector<double> t;
  for (std::size_t k = 0; k + 1 < w.size(); ++k)
    if ((w[k] > 0) != (w[k + 1] > 0)) t.push_back(dt * (k + w[k] / (w[k] - w[k + 1])));
  EXPECT_GE(t.size(), 3u) << "too few zero crossings";
  if (t.size() < 2) return 0;
  return 2 * (t.back() - t.front()) / (t.size() - 1);
}

}  // namespace

TEST(MembraneDynamics, EigenFrequenciesOfPrestressedSquare) {
  const MembraneMesh mesh = squareMesh(16);
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneSolver s(mesh, squareOptions(), bc);
  const Eigen::MatrixXd K = dense(s.assembleTangent(0.0));
  const Eigen::MatrixXd M = dense(s.assembleConsistentMass());
  std::vector<int> zdofs, xydofs;
  const auto& boundary = mesh.boundaryNodes();
  for (lid_t i = 0; i < mesh.nNodes(); ++i) {
    if (std::binary_search(boundary.begin(), boundary.end(), i)) continue;
    zdofs.push_back(3 * i + 2);
    xydofs.push_back(3 * i);
    xydofs.push_back(3 * i + 1);
  }
  const int nz = static_cast<int>(zdofs.size());
  Eigen::MatrixXd Kz(nz, nz), Mz(nz, nz);
  for (int i = 0; i < nz; ++i)
    for (int j = 0; j < nz; ++j) {
      Kz(i, j) = K(zdofs[i], zdofs[j]);
      Mz(i, j) = M(zdofs[i], zdofs[j]);
    }
  double coupling = 0;
  for (int i : zdofs)
    for (int j : xydofs) coupling = std::max({coupling, std::abs(K(i, j)), std::abs(M(i, j))});
  EXPECT_LT(coupling, 1e-12 * K.cwiseAbs().maxCoeff()) << "in-plane/out-of-plane coupling at the flat state";
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kz, Mz);
  ASSERT_EQ(eig.info(), Eigen::Success);
  const Eigen::VectorXd lam = eig.eigenvalues();
  const int modes[6][2] = {{1, 1}, {1, 2}, {2, 1}, {2, 2}, {1, 3}, {3, 1}};
  for (int k = 0; k < 6; ++k) {
    const double f = std::sqrt(lam(k)) / (2 * kPi), fe = exactFrequency(modes[k][0], modes[k][1]);
    std::printf("mode %d (%d,%d): f = %.5f Hz, exact %.5f, rel.err %.2e\n", k, modes[k][0], modes[k][1], f, fe,
                f / fe - 1);
    // Bilinear elements with consistent mass overestimate by ~ (k h)^2 / 24 per direction.
    EXPECT_TRUE(near(f, fe, Tol{0, k < 4 ? 0.01 : 0.015}, "frequency of mode " + std::to_string(k)));
    EXPECT_GT(f, fe) << "consistent mass bounds the frequencies from above";
  }
}

TEST(MembraneDynamics, NewmarkPeriodFromZeroCrossings) {
  const double T = 1 / exactFrequency(1, 1), dt = T / 40;
  for (auto mass : {MembraneMassType::Consistent, MembraneMassType::Lumped}) {
    MembraneOptions opt = squareOptions();
    opt.dynamics.mass = mass;
    const auto w = vibrate(opt, 16, 100, dt);
    const double period = periodFromZeroCrossings(w, dt);
    std::printf("%s mass: period %.6f s, exact %.6f, rel.err %.2e\n",
                mass == MembraneMassType::Consistent ? "consistent" : "lumped", period, T, period / T - 1);
    EXPECT_TRUE(near(period, T, Tol{0, 0.01}, "period"));
    // Average acceleration conserves energy: no amplitude loss over 2.5 periods.
    double peak = 0;
    for (std::size_t k = w.size() - 45; k < w.size(); ++k) peak = std::max(peak, std::abs(w[k]));
    EXPECT_TRUE(near(peak, w.front(), Tol{0, 0.01}, "amplitude kept"));
  }
}

TEST(MembraneDynamics, GeneralizedAlphaPeriodAndDissipation) {
  const double T = 1 / exactFrequency(1, 1), dt = T / 40;
  MembraneOptions opt = squareOptions();
  opt.dynamics.integrator = MembraneTimeIntegrator::GeneralizedAlpha;
  opt.dynamics.rhoInfinity = 0.6;
  const auto w = vibrate(opt, 12, 100, dt);
  const double period = periodFromZeroCrossings(w, dt);
  std::printf("generalized-alpha: period %.6f s, exact %.6f, rel.err %.2e\n", period, T, period / T - 1);
  EXPECT_TRUE(near(period, T, Tol{0, 0.01}, "period"));
  // Second-order accurate with small dissipation on a well-resolved mode: amplitude within 2 %.
  double peak = 0;
  for (std::size_t k = w.size() - 45; k < w.size(); ++k) peak = std::max(peak, std::abs(w[k]));
  EXPECT_LT(peak, w.front());
  EXPECT_GT(peak, 0.98 * w.front());
}

TEST(MembraneDynamics, RayleighDampingDecrement) {
  const double T = 1 / exactFrequency(1, 1), dt = T / 40, omega = 2 * kPi / T;
  const double zetaMass = 0.01, zetaStiff = 0.01;
  MembraneOptions opt = squareOptions();
  opt.dynamics.rayleighAlpha = 2 * zetaMass * omega;
  opt.dynamics.rayleighBeta = 2 * zetaStiff / omega;
  const auto w = vibrate(opt, 12, 100, dt);
  // Positive peaks by parabolic interpolation.
  std::vector<double> peaks;
  for (std::size_t k = 1; k + 1 < w.size(); ++k)
    if (w[k] > w[k - 1] && w[k] >= w[k + 1]) {
      const double a = 0.5 * (w[k - 1] - 2 * w[k] + w[k + 1]), b = 0.5 * (w[k + 1] - w[k - 1]);
      peaks.push_back(w[k] - b * b / (4 * a));
    }
  ASSERT_GE(peaks.size(), 2u);
  const double delta = std::log(peaks.front() / peaks.back()) / (peaks.size() - 1);
  const double zeta = zetaMass + zetaStiff;
  const double exact = 2 * kPi * zeta / std::sqrt(1 - zeta * zeta);
  std::printf("Rayleigh: log decrement %.5f, exact %.5f, rel.err %.2e\n", delta, exact, delta / exact - 1);
  EXPECT_TRUE(near(delta, exact, Tol{0, 0.03}, "logarithmic decrement"));
}
