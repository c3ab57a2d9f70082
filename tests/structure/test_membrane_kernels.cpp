// Element kernels against independent serial host code, on a curved mixed quad/triangle mesh
// with a random large displacement:
//  - internal + follower-pressure forces vs a host implementation in curvilinear (covariant)
//    form, which uses no local orthonormal basis at all;
//  - the tangent vs central finite differences of the residual (material + geometric, with the
//    tension-field model, and the symmetrised pressure stiffness vs the symmetric part of the
//    finite-difference matrix);
//  - the no-atomics gathers vs serial host sums, and bitwise repeatability.
#include "support/Approx.hpp"
#include "support/DenseCsr.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <random>

using namespace mfsi;
using mfsi::test::dense;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

/// Curved mixed mesh: a jittered 4 x 3 quad grid lifted onto z = 0.3 sin(2x) cos(y), every
/// third quad split into two triangles.
MembraneMesh curvedMixedMesh() {
  MembraneRectangleSpec rect;
  rect.lx = 1.2;
  rect.ly = 0.9;
  rect.nx = 4;
  rect.ny = 3;
  rect.jitter = 0.2;
  MembraneMeshInput in = generateRectangleMesh(rect);
  for (auto& p : in.points) p[2] = 0.3 * std::sin(2 * p[0]) * std::cos(p[1]);
  std::vector<std::array<lid_t, 4>> els;
  for (std::size_t e = 0; e < in.elements.size(); ++e) {
    const auto q = in.elements[e];
    if (e % 3 == 1) {
      els.push_back({q[0], q[1], q[2], -1});
      els.push_back({q[0], q[2], q[3], -1});
    } else {
      els.push_back(q);
    }
  }
  in.elements = els;
  return buildMembraneMesh(in);
}

std::vector<double> randomDisplacement(lid_t nNodes, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-amplitude, amplitude);
  std::vector<double> u(3 * nNodes);
  for (auto& v : u) v = uni(rng);
  return u;
}

/// A host copy that never aliases the source (create_mirror_view_and_copy returns the same View
/// when the memory space is already host-accessible).
std::vector<double> copyToHost(const RealView& v) {
  auto h = Kokkos::create_mirror(v);
  Kokkos::deep_copy(h, v);
  return std::vector<double>(h.data(), h.data() + h.extent(0));
}

/// Host reference: element forces f_ext - f_int in covariant form. S^ab = lambda' G^ab G^cd E_cd +
/// mu (G^ac G^bd + G^ad G^bc) E_cd + (T0/h) G^ab with lambda' = E nu/(1 - nu^2), mu = E/(2(1+nu));
/// f_int,A = int h S^ab N_A,a g_b dA0; f_ext,A = int p N_A (g_1 x g_2) dxi deta.
std::vector<double> hostResidual(const MembraneMesh& mesh, const MembraneMaterial& m, const std::vector<double>& u,
                                 double p) {
  std::vector<double> R(3 * mesh.nNodes(), 0.0);
  const double lam = m.youngsModulus * m.poissonRatio / (1 - m.poissonRatio * m.poissonRatio);
  const double mu = m.youngsModulus / (2 * (1 + m.poissonRatio));
  for (const auto& el : mesh.hostElements()) {
    const int nv = el[3] < 0 ? 3 : 4;
    std::vector<std::array<double, 3>> gps;  // xi, eta, weight
    if (nv == 4) {
      const double q = 1 / std::sqrt(3.0);
      gps = {{-q, -q, 1}, {q, -q, 1}, {q, q, 1}, {-q, q, 1}};
    } else {
      gps = {{1.0 / 3, 1.0 / 3, 0.5}};
    }
    for (const auto& gp : gps) {
      const double xi = gp[0], eta = gp[1];
      double N[4], dN[4][2];
      if (nv == 4) {
        const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
        for (int a = 0; a < 4; ++a) {
          N[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
          dN[a][0] = 0.25 * sx[a] * (1 + sy[a] * eta);
          dN[a][1] = 0.25 * sy[a] * (1 + sx[a] * xi);
        }
      } else {
        N[0] = 1 - xi - eta, N[1] = xi, N[2] = eta;
        dN[0][0] = -1, dN[0][1] = -1, dN[1][0] = 1, dN[1][1] = 0, dN[2][0] = 0, dN[2][1] = 1;
      }
      Eigen::Vector3d G[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
      Eigen::Vector3d g[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
      for (int a = 0; a < nv; ++a) {
        const auto& X = mesh.hostPoints()[el[a]];
        const Eigen::Vector3d Xa(X[0], X[1], X[2]);
        const Eigen::Vector3d xa = Xa + Eigen::Vector3d(u[3 * el[a]], u[3 * el[a] + 1], u[3 * el[a] + 2]);
        for (int al = 0; al < 2; ++al) {
          G[al] += dN[a][al] * Xa;
          g[al] += dN[a][al] * xa;
        }
      }
      Eigen::Matrix2d Gm, gm;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          Gm(i, j) = G[i].dot(G[j]);
          gm(i, j) = g[i].dot(g[j]);
        }
      const Eigen::Matrix2d Gi = Gm.inverse();
      const Eigen::Matrix2d Ec = 0.5 * (gm - Gm);
      const double trace = (Gi * Ec).trace();  // G^cd E_cd
      const Eigen::Matrix2d S = lam * trace * Gi + 2 * mu * Gi * Ec * Gi + (m.preStress / m.thickness) * Gi;
      const double J = std::sqrt(Gm.determinant());
      const Eigen::Vector3d area = g[0].cross(g[1]);
      for (int a = 0; a < nv; ++a) {
        Eigen::Vector3d f = Eigen::Vector3d::Zero();
        for (int al = 0; al < 2; ++al)
          for (int be = 0; be < 2; ++be) f += m.thickness * S(al, be) * dN[a][al] * g[be];
        const Eigen::Vector3d r = gp[2] * (p * N[a] * area - J * f);
        for (int k = 0; k < 3; ++k) R[3 * el[a] + k] += r[k];
      }
    }
  }
  return R;
}

}  // namespace

TEST(MembraneKernels, ResidualMatchesSerialHostOnCurvedMixedMesh) {
  const MembraneMesh mesh = curvedMixedMesh();
  ASSERT_GT(mesh.nTriangles(), 0);
  ASSERT_GT(mesh.nQuads(), 0);
  MembraneOptions opt;
  opt.material = {3e6, 0.3, 2e-3, 0, 40.0};
  const double p = 250.0;
  MembraneLoads loads;
  loads.pressure = p;
  MembraneSolver solver(mesh, opt, {}, loads);
  const auto u = randomDisplacement(mesh.nNodes(), 0.05, 11);
  Kokkos::deep_copy(solver.displacement(), toDevice(u, "u"));
  const auto R = copyToHost(solver.residual(0.0));
  const auto ref = hostResidual(mesh, opt.material, u, p);
  double scale = 0;
  for (double v : ref) scale = std::max(scale, std::abs(v));
  ASSERT_GT(scale, 1.0);
  for (std::size_t i = 0; i < ref.size(); ++i)
    ASSERT_TRUE(near(R[i], ref[i], Tol{1e-11 * scale, 0}, "residual dof " + std::to_string(i)));
}

namespace {

/// Central finite-difference matrix of -R (so it approximates the tangent), columns j.
Eigen::MatrixXd finiteDifferenceTangent(MembraneSolver& s, const std::vector<double>& u, double h) {
  const int n = static_cast<int>(u.size());
  Eigen::MatrixXd K(n, n);
  for (int j = 0; j < n; ++j) {
    std::vector<double> up = u, um = u;
    up[j] += h;
    um[j] -= h;
    Kokkos::deep_copy(s.displacement(), toDevice(up, "u+"));
    const auto Rp = copyToHost(s.residual(0.0));
    Kokkos::deep_copy(s.displacement(), toDevice(um, "u-"));
    const auto Rm = copyToHost(s.residual(0.0));
    for (int i = 0; i < n; ++i) K(i, j) = -(Rp[i] - Rm[i]) / (2 * h);
  }
  Kokkos::deep_copy(s.displacement(), toDevice(u, "u"));
  return K;
}

void checkTangent(MembraneWrinklingModel wrinkling, double pressure, bool symmetricPart) {
  const MembraneMesh mesh = curvedMixedMesh();
  MembraneOptions opt;
  opt.material = {3e6, 0.3, 2e-3, 0, 40.0};
  opt.wrinkling = wrinkling;
  opt.wrinklingStiffnessFraction = 0;  // exact tangent (no safeguard) for the comparison
  opt.newton.tangentStressFloor = 0;
  // Two bars and a spring exercise the line items too.
  MembraneBoundary bc;
  bc.edgeBeams = makeEdgeBeams({0, 1, 2}, 5e3, false);
  bc.edgeSprings.push_back({7, {0.5, 0.5, 1.5}, 300.0, 0.7});
  MembraneLoads loads;
  loads.pressure = pressure;
  MembraneSolver s(mesh, opt, bc, loads);
  const auto u = randomDisplacement(mesh.nNodes(), 0.04, 5);
  Kokkos::deep_copy(s.displacement(), toDevice(u, "u"));
  Eigen::MatrixXd Kfd = finiteDifferenceTangent(s, u, 1e-7);
  const Eigen::MatrixXd K = dense(s.assembleTangent(0.0, true));
  if (symmetricPart) Kfd = 0.5 * (Kfd + Kfd.transpose()).eval();
  const double scale = Kfd.cwiseAbs().maxCoeff();
  for (int i = 0; i < K.rows(); ++i)
    for (int j = 0; j < K.cols(); ++j)
      ASSERT_TRUE(near(K(i, j), Kfd(i, j), Tol{2e-6 * scale, 0},
                       "K(" + std::to_string(i) + "," + std::to_string(j) + ")"));
  // The wrinkling case must actually visit the three states, or it proves little.
  if (wrinkling == MembraneWrinklingModel::TensionField) {
    const auto sum = s.summary();
    EXPECT_GT(sum.at("wrinkledFraction"), 0.0);
    EXPECT_LT(sum.at("wrinkledFraction") + sum.at("slackFraction"), 1.0);
  }
}

}  // namespace

TEST(MembraneKernels, TangentMatchesFiniteDifferences) { checkTangent(MembraneWrinklingModel::None, 0.0, false); }

TEST(MembraneKernels, TensionFieldTangentMatchesFiniteDifferences) {
  checkTangent(MembraneWrinklingModel::TensionField, 0.0, false);
}

TEST(MembraneKernels, SymmetrisedPressureStiffnessIsSymmetricPartOfExactTangent) {
  checkTangent(MembraneWrinklingModel::None, 250.0, true);
}

TEST(MembraneKernels, GatherEqualsSerialHostSumAndIsRepeatable) {
  const MembraneMesh mesh = curvedMixedMesh();
  std::vector<std::array<lid_t, 4>> items = mesh.hostElements();
  items.push_back({3, 4, -1, -1});
  items.push_back({9, -1, -1, -1});
  const lid_t nI = static_cast<lid_t>(items.size());
  const CsrAssemblyMap map = buildCsrAssemblyMap(items, mesh.nNodes(), 3, "test::assembly");
  ItemValuesView vec("vec", nI, 12), mat("mat", nI, 144);
  auto hv = Kokkos::create_mirror_view(vec);
  auto hm = Kokkos::create_mirror_view(mat);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (lid_t i = 0; i < nI; ++i) {
    for (int k = 0; k < 12; ++k) hv(i, k) = uni(rng);
    for (int k = 0; k < 144; ++k) hm(i, k) = uni(rng);
  }
  Kokkos::deep_copy(vec, hv);
  Kokkos::deep_copy(mat, hm);
  ExecSpace exec;
  RealView out1("out1", 3 * mesh.nNodes()), out2("out2", 3 * mesh.nNodes());
  gatherItemVectors(exec, map, vec, out1);
  gatherItemVectors(exec, map, vec, out2);
  CsrMatrix A = makeMatrix(map, "A"), B = makeMatrix(map, "B");
  gatherItemMatrices(exec, map, mat, A);
  gatherItemMatrices(exec, map, mat, B);
  exec.fence();
  // Serial host assembly in item order.
  std::vector<double> ref(3 * mesh.nNodes(), 0.0);
  Eigen::MatrixXd Kref = Eigen::MatrixXd::Zero(3 * mesh.nNodes(), 3 * mesh.nNodes());
  for (lid_t i = 0; i < nI; ++i)
    for (int a = 0; a < 4; ++a) {
      if (items[i][a] < 0) continue;
      for (int k = 0; k < 3; ++k) {
        ref[3 * items[i][a] + k] += hv(i, 3 * a + k);
        for (int b = 0; b < 4; ++b) {
          if (items[i][b] < 0) continue;
          for (int l = 0; l < 3; ++l) Kref(3 * items[i][a] + k, 3 * items[i][b] + l) += hm(i, (3 * a + k) * 12 + 3 * b + l);
        }
      }
    }
  auto h1 = Kokkos::create_mirror_view_and_copy(HostSpace(), out1);
  auto h2 = Kokkos::create_mirror_view_and_copy(HostSpace(), out2);
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ASSERT_TRUE(near(h1(i), ref[i], Tol{1e-13, 0}, "gathered vector " + std::to_string(i)));
    ASSERT_EQ(h1(i), h2(i)) << "not bitwise repeatable at " << i;
  }
  const Eigen::MatrixXd Ad = dense(A), Bd = dense(B);
  EXPECT_LT((Ad - Kref).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_EQ((Ad - Bd).cwiseAbs().maxCoeff(), 0.0);
}
