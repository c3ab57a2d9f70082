// Patch test: an irregular flat patch whose boundary follows a homogeneous large deformation
// x = R F X (stretch and shear F, then a 3D rigid rotation R) must reproduce it exactly inside,
// with the exact uniform Green-Lagrange strain E = (F^T F - I)/2 and PK2 stress
// S = C E + T0/h I in every element, whatever the element shapes. Quads and triangles.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

using namespace mfsi;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

void runPatch(MembraneElementType type) {
  MembraneRectangleSpec rect;
  rect.lx = 1.0;
  rect.ly = 0.8;
  rect.nx = 5;
  rect.ny = 4;
  rect.jitter = 0.3;
  rect.seed = 7;
  rect.type = type;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));

  const double E = 2e5, nu = 0.35, h = 0.01, T0 = 12.0;
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 0) = 1.10;
  F(0, 1) = 0.05;
  F(1, 0) = 0.02;
  F(1, 1) = 1.04;
  const double angle = 0.4;
  const RigidPlacement R = RigidPlacement::rotationAbout({1, 1, 1}, angle, {0, 0, 0});

  MembraneClamp clamp;
  clamp.nodes = mesh.boundaryNodes();
  for (lid_t n : clamp.nodes) {
    const auto& X = mesh.hostPoints()[n];
    const Eigen::Vector3d x = F * Eigen::Vector3d(X[0], X[1], X[2]);
    clamp.offsets.push_back({x[0] - X[0], x[1] - X[1], x[2] - X[2]});
  }
  clamp.frame = [R](real) { return R; };
  MembraneBoundary bc;
  bc.clamps.push_back(clamp);

  MembraneOptions opt;
  opt.material = {E, nu, h, 0, T0};
  opt.tolerance = 1e-11;
  MembraneSolver solver(mesh, opt, bc);
  const MembraneSolveReport rep = solver.solveStatic();
  ASSERT_TRUE(rep.converged) << "relative residual " << rep.relativeResidual;

  // Exact strain and stress.
  const Eigen::Matrix2d F2 = F.topLeftCorner<2, 2>();
  const Eigen::Matrix2d Eg = 0.5 * (F2.transpose() * F2 - Eigen::Matrix2d::Identity());
  const double c = E / (1 - nu * nu);
  const double S11 = c * (Eg(0, 0) + nu * Eg(1, 1)) + T0 / h;
  const double S22 = c * (Eg(1, 1) + nu * Eg(0, 0)) + T0 / h;
  const double S12 = c * (1 - nu) / 2 * 2 * Eg(0, 1);
  const MembraneResults res = solver.results();
  auto strain = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.strain);
  auto stress = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.stress);
  auto disp = Kokkos::create_mirror_view_and_copy(HostSpace(), res.displacement);
  const Tol tolS{1e-8 * S11, 0}, tolE{1e-10, 0};
  for (lid_t e = 0; e < mesh.nElements(); ++e) {
    ASSERT_TRUE(near(strain(e, 0), Eg(0, 0), tolE, "E11 of element " + std::to_string(e)));
    ASSERT_TRUE(near(strain(e, 1), Eg(1, 1), tolE, "E22 of element " + std::to_string(e)));
    ASSERT_TRUE(near(strain(e, 2), 2 * Eg(0, 1), tolE, "2 E12 of element " + std::to_string(e)));
    ASSERT_TRUE(near(stress(e, 0), S11, tolS, "S11 of element " + std::to_string(e)));
    ASSERT_TRUE(near(stress(e, 1), S22, tolS, "S22 of element " + std::to_string(e)));
    ASSERT_TRUE(near(stress(e, 2), S12, tolS, "S12 of element " + std::to_string(e)));
  }
  // Interior nodes sit on the homogeneous deformation.
  for (lid_t n = 0; n < mesh.nNodes(); ++n) {
    const auto& X = mesh.hostPoints()[n];
    const Eigen::Vector3d fx = F * Eigen::Vector3d(X[0], X[1], X[2]);
    const auto x = R.apply({fx[0], fx[1], fx[2]});
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(near(disp(n, k), x[k] - X[k], Tol{1e-10, 0}, "u of node " + std::to_string(n)));
  }
}

}  // namespace

TEST(MembranePatch, IrregularQuadsReproduceUniformStress) { runPatch(MembraneElementType::Quad4); }

TEST(MembranePatch, IrregularTrianglesReproduceUniformStress) { runPatch(MembraneElementType::Tri3); }
