// Tension-field wrinkling model.
//  - Material point: the three states, continuity of the stress across the state boundaries and
//    the consistent tangent against finite differences of the stress.
//  - Homogeneous panels (all boundary nodes on an affine map): taut, wrinkled (uniaxial tension
//    E e1 along the major strain direction, also rotated by shear) and slack states with the
//    exact stresses; with the model off the same panel shows the compressive elastic s2.
//  - Sheared annulus (hub rotated inside a pre-tensioned membrane): with the model off, s2
//    follows the linear solution sigma0 - 2 G B / r^2 and is compressive inside
//    r_w = sqrt(2 G B / sigma0); with the model on, s2 >= 0 everywhere and the wrinkled region
//    is the annulus ri < r < r_w of tension-field theory (solved numerically below), which also
//    predicts the drop of the hub torque.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>

using namespace mfsi;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {
const double kPi = std::acos(-1.0);
}

TEST(MembraneWrinkling, MaterialPointStatesAndContinuity) {
  const double E = 1e6, nu = 0.3;
  real S[3], C[3][3];
  // Taut: biaxial tension.
  {
    const real e[3] = {0.01, 0.005, 0.002};
    EXPECT_EQ(membrane::tensionField(E, nu, 0, e, S, C), MembraneWrinkleState::Taut);
    const double f = E / (1 - nu * nu);
    EXPECT_TRUE(near(S[0], f * (0.01 + nu * 0.005), Tol{1e-9, 0}));
    EXPECT_TRUE(near(S[2], f * (1 - nu) / 2 * 0.002, Tol{1e-9, 0}));
  }
  // Wrinkled: uniaxial along x with lateral strain below -nu e1.
  {
    const real e[3] = {0.01, -0.004, 0};
    EXPECT_EQ(membrane::tensionField(E, nu, 0, e, S, C), MembraneWrinkleState::Wrinkled);
    EXPECT_TRUE(near(S[0], E * 0.01, Tol{1e-9, 0}));
    EXPECT_TRUE(near(S[1], 0, Tol{1e-9, 0}));
    EXPECT_TRUE(near(S[2], 0, Tol{1e-9, 0}));
  }
  // Slack: both principal strains compressive.
  {
    const real e[3] = {-0.01, -0.004, 0.001};
    EXPECT_EQ(membrane::tensionField(E, nu, 0, e, S, C), MembraneWrinkleState::Slack);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(S[i], 0.0);
  }
  // Continuity at the taut/wrinkled boundary e2 = -nu e1 (principal axes rotated by 30 degrees).
  const double e1 = 0.01, t = kPi / 6, c = std::cos(t), s = std::sin(t);
  for (double e2 : {-nu * e1 * (1 - 1e-9), -nu * e1 * (1 + 1e-9)}) {
    const real e[3] = {e1 * c * c + e2 * s * s, e1 * s * s + e2 * c * c, 2 * (e1 - e2) * c * s};
    membrane::tensionField(E, nu, 0, e, S, C);
    EXPECT_TRUE(near(S[0], E * e1 * c * c, Tol{1e-4, 0}));
    EXPECT_TRUE(near(S[1], E * e1 * s * s, Tol{1e-4, 0}));
    EXPECT_TRUE(near(S[2], E * e1 * c * s, Tol{1e-4, 0}));
  }
}

TEST(MembraneWrinkling, ConsistentTangentInEveryState) {
  const double E = 1e6, nu = 0.3;
  const real points[3][3] = {{0.01, 0.005, 0.002}, {0.01, -0.006, 0.004}, {-0.01, -0.004, 0.001}};
  for (const auto& e0 : points) {
    real S[3], C[3][3];
    membrane::tensionField(E, nu, 0, e0, S, C);
    const double h = 1e-8;
    for (int j = 0; j < 3; ++j) {
      real ep[3] = {e0[0], e0[1], e0[2]}, em[3] = {e0[0], e0[1], e0[2]};
      ep[j] += h;
      em[j] -= h;
      real Sp[3], Sm[3], Cd[3][3];
      membrane::tensionField(E, nu, 0, ep, Sp, Cd);
      membrane::tensionField(E, nu, 0, em, Sm, Cd);
      for (int i = 0; i < 3; ++i) EXPECT_TRUE(near(C[i][j], (Sp[i] - Sm[i]) / (2 * h), Tol{1e-3 * E, 0}));
    }
  }
}

TEST(MembraneWrinkling, ResidualStiffnessBlendsTheElasticLaw) {
  // N = (1 - f) N_tf + f h C E in the wrinkled and slack states, the elastic law where taut: the
  // slack point now resists (f h C E), the wrinkled one carries f of its compression, the stress
  // stays continuous across the taut/wrinkled boundary and the tangent is the stress's derivative.
  const double E = 1e6, nu = 0.3, h = 1e-3, f = 0.01;
  membrane::MembraneLaw law;
  law.E = E;
  law.nu = nu;
  law.h = h;
  law.eta = 0;
  law.wrinkling = true;
  law.residual = f;
  real C[3][3];
  membrane::planeStressMatrix(E, nu, C);
  const real points[4][3] = {{0.01, 0.005, 0.002}, {0.01, -0.006, 0.004}, {-0.01, -0.004, 0.001}, {0.01, -0.004, 0}};
  for (const auto& e : points) {
    real N[3], Ct[3][3], Sf[3], Cf[3][3];
    const auto state = law.evaluate(e, N, Ct);
    EXPECT_EQ(membrane::tensionField(E, nu, 0, e, Sf, Cf), state);
    for (int i = 0; i < 3; ++i) {
      const double elastic = C[i][0] * e[0] + C[i][1] * e[1] + C[i][2] * e[2];
      const double expected = state == MembraneWrinkleState::Taut ? elastic : (1 - f) * Sf[i] + f * elastic;
      EXPECT_TRUE(near(N[i], h * expected, Tol{1e-9, 1e-12}));
    }
    const double d = 1e-8;
    for (int j = 0; j < 3; ++j) {
      real ep[3] = {e[0], e[1], e[2]}, em[3] = {e[0], e[1], e[2]}, Np[3], Nm[3], Cd[3][3];
      ep[j] += d;
      em[j] -= d;
      law.evaluate(ep, Np, Cd);
      law.evaluate(em, Nm, Cd);
      for (int i = 0; i < 3; ++i) EXPECT_TRUE(near(Ct[i][j], (Np[i] - Nm[i]) / (2 * d), Tol{1e-3 * E * h, 0}));
    }
  }
  // The slack point resists: its stress is f times the elastic one, not zero.
  real N[3], Ct[3][3];
  const real slack[3] = {-0.01, -0.004, 0.001};
  law.evaluate(slack, N, Ct);
  EXPECT_TRUE(near(N[0], f * h * (C[0][0] * slack[0] + C[0][1] * slack[1]), Tol{0, 1e-12}));
  EXPECT_LT(N[0], 0);
  // Continuity at the taut/wrinkled boundary e2 = -nu e1.
  const double e1 = 0.01;
  real Na[3], Nb[3];
  const real ea[3] = {e1, -nu * e1 * (1 - 1e-9), 0}, eb[3] = {e1, -nu * e1 * (1 + 1e-9), 0};
  EXPECT_EQ(law.evaluate(ea, Na, Ct), MembraneWrinkleState::Taut);
  EXPECT_EQ(law.evaluate(eb, Nb, Ct), MembraneWrinkleState::Wrinkled);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(near(Na[i], Nb[i], Tol{1e-6 * E * h * e1, 0}));
}

namespace {

struct PanelResult {
  std::vector<double> S11, S22, S12, s2;
  std::vector<int> state;
  bool converged = false;
};

/// Square panel, all boundary nodes on x = F X, solved from rest.
PanelResult homogeneousPanel(const Eigen::Matrix2d& F, MembraneWrinklingModel model) {
  MembraneRectangleSpec rect;
  rect.nx = rect.ny = 4;
  rect.jitter = 0.2;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));
  MembraneClamp clamp;
  clamp.nodes = mesh.boundaryNodes();
  for (lid_t n : clamp.nodes) {
    const auto& X = mesh.hostPoints()[n];
    const Eigen::Vector2d x = F * Eigen::Vector2d(X[0], X[1]);
    clamp.offsets.push_back({x[0] - X[0], x[1] - X[1], 0});
  }
  MembraneBoundary bc;
  bc.clamps.push_back(clamp);
  MembraneOptions opt;
  opt.material = {1e6, 0.3, 1e-3, 0, 0};
  opt.wrinkling = model;
  opt.tolerance = 1e-10;
  MembraneSolver solver(mesh, opt, bc);
  PanelResult r;
  r.converged = solver.solveStatic().converged;
  const auto res = solver.results();
  auto S = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.stress);
  auto s2 = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.principal2);
  auto st = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.wrinkleState);
  auto gst = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.gaussWrinkleState);
  for (lid_t e = 0; e < mesh.nElements(); ++e) {
    // A homogeneous deformation: every Gauss point is in the element's state. (Not for slack
    // panels: without stiffness their interior nodes need not sit at the homogeneous positions.)
    const int nGauss = mesh.hostElements()[e][3] < 0 ? 1 : 4;
    if (st(e) != static_cast<int>(MembraneWrinkleState::Slack)) {
      for (int q = 0; q < nGauss; ++q) {
        EXPECT_EQ(gst(e, q), st(e)) << "element " << e << " Gauss point " << q;
      }
    }
    r.S11.push_back(S(e, 0));
    r.S22.push_back(S(e, 1));
    r.S12.push_back(S(e, 2));
    r.s2.push_back(s2(e));
    r.state.push_back(st(e));
  }
  return r;
}

}  // namespace

TEST(MembraneWrinkling, HomogeneousPanelsTautWrinkledSlack) {
  const double E = 1e6, nu = 0.3, f = E / (1 - nu * nu);
  const int wrinkled = static_cast<int>(MembraneWrinkleState::Wrinkled);
  // Stretched in x, squeezed in y: wrinkled, tension E e1 along x.
  {
    Eigen::Matrix2d F;
    F << 1.02, 0, 0, 0.99;
    const double E11 = 0.5 * (1.02 * 1.02 - 1), E22 = 0.5 * (0.99 * 0.99 - 1);
    const PanelResult on = homogeneousPanel(F, MembraneWrinklingModel::TensionField);
    const PanelResult off = homogeneousPanel(F, MembraneWrinklingModel::None);
    ASSERT_TRUE(on.converged && off.converged);
    for (std::size_t e = 0; e < on.S11.size(); ++e) {
      EXPECT_EQ(on.state[e], wrinkled);
      EXPECT_TRUE(near(on.S11[e], E * E11, Tol{1e-6 * E * E11, 0}, "wrinkled S11"));
      EXPECT_TRUE(near(on.S22[e], 0, Tol{1e-6 * E * E11, 0}, "wrinkled S22"));
      EXPECT_TRUE(near(off.s2[e], f * (E22 + nu * E11), Tol{1e-6 * E * E11, 0}, "elastic compressive s2"));
      EXPECT_LT(off.s2[e], -0.1 * E * E11);
    }
  }
  // Simple shear: wrinkles along the 45-degree-ish major strain direction.
  {
    Eigen::Matrix2d F;
    F << 1.0, 0.03, 0, 1.0;
    const Eigen::Matrix2d Eg = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Eg);
    const double e1 = es.eigenvalues()(1);
    const Eigen::Vector2d n = es.eigenvectors().col(1);
    const PanelResult on = homogeneousPanel(F, MembraneWrinklingModel::TensionField);
    ASSERT_TRUE(on.converged);
    for (std::size_t e = 0; e < on.S11.size(); ++e) {
      EXPECT_EQ(on.state[e], wrinkled);
      EXPECT_TRUE(near(on.S11[e], E * e1 * n(0) * n(0), Tol{1e-6 * E * e1, 0}, "shear-wrinkled S11"));
      EXPECT_TRUE(near(on.S22[e], E * e1 * n(1) * n(1), Tol{1e-6 * E * e1, 0}, "shear-wrinkled S22"));
      EXPECT_TRUE(near(on.S12[e], E * e1 * n(0) * n(1), Tol{1e-6 * E * e1, 0}, "shear-wrinkled S12"));
      EXPECT_TRUE(near(on.s2[e], 0, Tol{1e-6 * E * e1, 0}, "no compression"));
    }
  }
  // Squeezed both ways: slack, no stress.
  {
    Eigen::Matrix2d F;
    F << 0.99, 0, 0, 0.98;
    const PanelResult on = homogeneousPanel(F, MembraneWrinklingModel::TensionField);
    ASSERT_TRUE(on.converged);
    for (std::size_t e = 0; e < on.S11.size(); ++e) {
      EXPECT_EQ(on.state[e], static_cast<int>(MembraneWrinkleState::Slack));
      EXPECT_EQ(on.S11[e], 0.0);
      EXPECT_EQ(on.S22[e], 0.0);
    }
  }
}

namespace {

struct AnnulusCase {
  double ri = 0.2, ro = 1.0, E = 1e7, nu = 0.3, h = 1e-3, phi = 0.002, rw = 0.45;
  double G() const { return E / (2 * (1 + nu)); }
  /// Linear solution u_theta = A r + B / r with u_theta(ro) = 0, u_theta(ri) = phi ri.
  double B() const { return phi * ri * ri * ro * ro / (ro * ro - ri * ri); }
  /// Pre-stress that puts the linear wrinkle radius at rw.
  double sigma0() const { return 2 * G() * B() / (rw * rw); }
};

/// Tension-field theory of the sheared annulus (small strain; Mikulas 1964 style, for the
/// constitutive law of MembraneWrinkling.hpp), solved numerically. Unknowns: the wrinkle radius
/// rw and the ratio kappa = sigma_r / sigma_theta on the taut side of rw.
///  Taut zone rw < r < ro: u = a (r - ro^2/r), u_theta = A r + B'/r with u(ro) = u_theta(ro) = 0;
///    sigma_r = s0 + a P, sigma_theta = s0 + a Q, P,Q = E/(1-nu) +- E/(1+nu) ro^2/r^2; shear
///    tau = c / r^2, c = -2 G B'; at rw the elastic minor stress vanishes:
///    sigma_r sigma_theta = tau^2.
///  Wrinkled zone ri < r < rw: uniaxial stress along the tension rays at angle alpha,
///    tan alpha = tau / sigma_r; equilibrium gives (r sigma_r)^2 = K - c^2/r^2 (K from continuity
///    of sigma_r). Kinematics (the rays are the major strain direction, strain along them
///    sigma_1 / E - e0): u' = t^2 u/r + (1 - t^2) rho, (u_theta / r)' = 2 t (rho - u/r) / r with
///    t = tan alpha, rho = sigma_1/E - e0.
///  Conditions at the hub: u(ri) = 0, u_theta(ri) = phi ri.
struct TensionFieldAnnulus {
  const AnnulusCase& c;
  double s0, e0, k1, k2;
  explicit TensionFieldAnnulus(const AnnulusCase& cs)
      : c(cs), s0(cs.sigma0()), e0(cs.sigma0() * (1 - cs.nu) / cs.E), k1(cs.E / (1 - cs.nu)), k2(cs.E / (1 + cs.nu)) {}

  /// Residuals {u(ri)/ri, u_theta(ri)/(phi ri) - 1} and the hub torque constant c; false if the
  /// stress field does not exist for these unknowns.
  bool eval(double rw, double kappa, double F[2], double& cc, int n = 2000) const {
    const double rho2 = (c.ro / rw) * (c.ro / rw);
    const double P = k1 + k2 * rho2, Q = k1 - k2 * rho2;
    const double a = s0 * (kappa - 1) / (P - kappa * Q);
    const double sr = s0 + a * P, st = s0 + a * Q;
    if (!(sr > 0 && st > 0)) return false;
    cc = -rw * rw * std::sqrt(sr * st);  // tau < 0 for a positive hub rotation
    const double K = rw * rw * sr * sr + cc * cc / (rw * rw);
    double u = a * (rw - c.ro * c.ro / rw);
    double w = -cc / (2 * c.G()) * (1 / (rw * rw) - 1 / (c.ro * c.ro));  // u_theta / r
    bool ok = true;
    auto f = [&](double r, double uu, double& du, double& dw) {
      const double q2 = K * r * r - cc * cc;
      if (q2 <= 0) {
        ok = false;
        du = dw = 0;
        return;
      }
      const double t = cc / std::sqrt(q2);
      const double srr = std::sqrt(K - cc * cc / (r * r)) / r;
      const double tau = cc / (r * r);
      const double rho = (srr + tau * tau / srr) / c.E - e0;
      du = t * t * uu / r + (1 - t * t) * rho;
      dw = 2 * t * (rho - uu / r) / r;
    };
    const double dr = (c.ri - rw) / n;
    double r = rw;
    for (int i = 0; i < n && ok; ++i) {  // RK4 from rw down to ri
      double k1u, k1w, k2u, k2w, k3u, k3w, k4u, k4w;
      f(r, u, k1u, k1w);
      f(r + dr / 2, u + dr / 2 * k1u, k2u, k2w);
      f(r + dr / 2, u + dr / 2 * k2u, k3u, k3w);
      f(r + dr, u + dr * k3u, k4u, k4w);
      u += dr / 6 * (k1u + 2 * k2u + 2 * k3u + k4u);
      w += dr / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
      r += dr;
    }
    F[0] = u / c.ri;
    F[1] = w / c.phi - 1;
    return ok && std::isfinite(F[0]) && std::isfinite(F[1]);
  }

  /// Newton on (rw, kappa) from the best point of a coarse feasible scan. Returns {rw, c}.
  std::array<double, 2> solve() const {
    double x[2] = {0, 0}, best = 1e300, F[2], cc;
    for (int i = 0; i <= 16; ++i)
      for (int j = 0; j <= 16; ++j) {
        const double rw = c.rw * (0.55 + 0.03 * i), kappa = 1.2 * std::pow(1.25, j);
        if (rw > c.ri * 1.05 && eval(rw, kappa, F, cc, 400) && std::abs(F[0]) + std::abs(F[1]) < best) {
          best = std::abs(F[0]) + std::abs(F[1]);
          x[0] = rw;
          x[1] = kappa;
        }
      }
    EXPECT_LT(best, 1e300) << "no feasible tension-field state found";
    for (int it = 0; it < 50; ++it) {
      if (!eval(x[0], x[1], F, cc)) break;
      double J[2][2], Fp[2], cp;
      for (int j = 0; j < 2; ++j) {
        double xp[2] = {x[0], x[1]};
        const double d = j == 0 ? 1e-7 : 1e-6;
        xp[j] += d;
        if (!eval(xp[0], xp[1], Fp, cp)) return {x[0], cc};
        J[0][j] = (Fp[0] - F[0]) / d;
        J[1][j] = (Fp[1] - F[1]) / d;
      }
      const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
      const double d0 = (F[0] * J[1][1] - F[1] * J[0][1]) / det, d1 = (J[0][0] * F[1] - J[1][0] * F[0]) / det;
      double lam = 1;
      for (; lam > 1e-4; lam /= 2) {
        double Fn[2], cn;
        if (eval(x[0] - lam * d0, x[1] - lam * d1, Fn, cn) &&
            std::abs(Fn[0]) + std::abs(Fn[1]) < std::abs(F[0]) + std::abs(F[1]))
          break;
      }
      x[0] -= lam * d0;
      x[1] -= lam * d1;
      if (std::abs(d0) < 1e-13) break;
    }
    eval(x[0], x[1], F, cc);
    EXPECT_LT(std::abs(F[0]) + std::abs(F[1]), 1e-8) << "tension-field annulus theory did not converge";
    return {x[0], cc};
  }
};

struct AnnulusResult {
  std::vector<double> r, s2, area;
  std::vector<int> state;
  double torque = 0;  ///< z-moment the hub applies to the membrane
  bool converged = false;
};

AnnulusResult shearedAnnulus(const AnnulusCase& c, MembraneWrinklingModel model) {
  MembraneAnnulusSpec spec;
  spec.innerRadius = c.ri;
  spec.outerRadius = c.ro;
  spec.nRadial = 16;
  spec.nTheta = 64;
  spec.radialGrading = 3;
  const MembraneMesh mesh = buildMembraneMesh(generateAnnulusMesh(spec));
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("outer"), {}, {}});
  MembraneClamp hub;
  hub.nodes = mesh.nodeSet("inner");
  const double phi = c.phi;
  hub.frame = [phi](real) { return RigidPlacement::rotationAbout({0, 0, 1}, phi, {0, 0, 0}); };
  bc.clamps.push_back(hub);
  MembraneOptions opt;
  opt.material = {c.E, c.nu, c.h, 0, c.sigma0() * c.h};
  opt.wrinkling = model;
  opt.tolerance = 1e-8;
  MembraneSolver solver(mesh, opt, bc);
  AnnulusResult out;
  out.converged = solver.solveStatic().converged;
  const auto res = solver.results();
  auto s2 = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.principal2);
  auto st = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.wrinkleState);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), res.displacement);
  for (lid_t e = 0; e < mesh.nElements(); ++e) {
    double x = 0, y = 0;
    for (int a = 0; a < 4; ++a) {
      x += 0.25 * mesh.hostPoints()[mesh.hostElements()[e][a]][0];
      y += 0.25 * mesh.hostPoints()[mesh.hostElements()[e][a]][1];
    }
    out.r.push_back(std::hypot(x, y));
    out.s2.push_back(s2(e));
    out.state.push_back(st(e));
    out.area.push_back(mesh.elementAreas()[e]);
  }
  // Support force at a clamped node = -R (R = f_ext - f_int).
  auto R = Kokkos::create_mirror(solver.residual(0.0));
  Kokkos::deep_copy(R, solver.residual(0.0));
  for (lid_t n : mesh.nodeSet("inner")) {
    const double x = mesh.hostPoints()[n][0] + u(n, 0), y = mesh.hostPoints()[n][1] + u(n, 1);
    out.torque += x * (-R(3 * n + 1)) - y * (-R(3 * n));
  }
  return out;
}

}  // namespace

TEST(MembraneWrinkling, ShearedAnnulusWrinklesWhereTensionFieldTheoryPutsIt) {
  const AnnulusCase c;
  const double s0 = c.sigma0(), pi = kPi;
  const AnnulusResult off = shearedAnnulus(c, MembraneWrinklingModel::None);
  const AnnulusResult on = shearedAnnulus(c, MembraneWrinklingModel::TensionField);
  ASSERT_TRUE(off.converged);
  ASSERT_TRUE(on.converged);
  const auto theory = TensionFieldAnnulus(c).solve();
  const double rwTheory = theory[0];
  // Model off: the linear solution, compressive inside the linear wrinkle radius.
  double worst = 0;
  for (std::size_t e = 0; e < off.r.size(); ++e) {
    const double lin = s0 - 2 * c.G() * c.B() / (off.r[e] * off.r[e]);
    worst = std::max(worst, std::abs(off.s2[e] - lin) / s0);
    if (off.r[e] < 0.9 * c.rw) {
      EXPECT_LT(off.s2[e], 0.0);
    }
  }
  EXPECT_LT(worst, 0.02) << "model off: s2 against the linear solution";
  const double torqueLinear = 2 * pi * c.h * 2 * c.G() * c.B();
  EXPECT_TRUE(near(off.torque, torqueLinear, Tol{0, 0.01}, "model off: hub torque"));
  // Model on: never compressive; wrinkled exactly in the annulus ri < r < rw of the theory.
  double minS2 = 1e300, wrinkledArea = 0, slackArea = 0, rMaxWrinkled = 0, rMinTaut = 1e300;
  for (std::size_t e = 0; e < on.r.size(); ++e) {
    minS2 = std::min(minS2, on.s2[e]);
    if (on.state[e] == static_cast<int>(MembraneWrinkleState::Wrinkled)) {
      wrinkledArea += on.area[e];
      rMaxWrinkled = std::max(rMaxWrinkled, on.r[e]);
    } else {
      if (on.state[e] == static_cast<int>(MembraneWrinkleState::Slack)) slackArea += on.area[e];
      rMinTaut = std::min(rMinTaut, on.r[e]);
    }
  }
  const double rwFe = std::sqrt(c.ri * c.ri + wrinkledArea / pi);
  std::printf("sheared annulus: wrinkle radius FE %.4f, tension-field theory %.4f, linear %.4f; hub torque / linear: "
              "FE %.4f, theory %.4f; min s2/sigma0 %.2e\n",
              rwFe, rwTheory, c.rw, on.torque / torqueLinear, 2 * pi * c.h * std::abs(theory[1]) / torqueLinear,
              minS2 / s0);
  EXPECT_GE(minS2, -1e-9 * s0);
  EXPECT_EQ(slackArea, 0.0);
  EXPECT_TRUE(near(rwFe, rwTheory, Tol{0, 0.02}, "wrinkle radius"));
  EXPECT_LT(rMaxWrinkled, rwTheory);  // every wrinkled element centre inside the theory's radius...
  EXPECT_GT(rMinTaut, 0.9 * rwTheory);  // ...and every taut one outside, up to one element
  EXPECT_TRUE(near(on.torque, 2 * pi * c.h * std::abs(theory[1]), Tol{0, 0.02}, "model on: hub torque"));
}
