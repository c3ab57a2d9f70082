// Schaefer & Turek (1996) 2D-1: steady flow past a cylinder in a channel at Re = 20. Published
// bounds: c_D in [5.57, 5.59], c_L in [0.0104, 0.0110], dp in [0.1172, 0.1176].
// - On the committed block-structured hex mesh cases/meshes/cylinder_medium.msh (7424 cells, one
//   cell thick) with the scene's settings (SIMPLEC), the coefficients fall in or next to the bounds.
// - SIMPLEC (pimple.consistent) converges to 1e-10 and to SIMPLE's solution (the converged fluxes
//   use rAU whatever the pressure equation uses, including the non-orthogonal part of the face
//   gradient), on the coarse block mesh and on an unstructured, graded Gmsh mesh. Both need the
//   steady momentum relaxation from max(|a_P|, sum |a_N|): without it SIMPLE (U 0.9, p 0.3) broke
//   down in its first iterations on the graded mesh.
#include "core/GmshReader.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/Loads.hpp"
#include "support/Approx.hpp"
#include "support/HostVectors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

FluidOptions cylinderOptions(bool consistent, double relaxU, double relaxP) {
  FluidOptions o;
  o.density = 1.0;
  o.viscosity = 1e-3;
  o.timeScheme = TimeScheme::Steady;
  o.pimple.nOuterCorrectors = 3000;
  o.pimple.nCorrectors = 1;
  o.pimple.nNonOrthogonalCorrectors = 0;
  o.pimple.consistent = consistent;
  o.pimple.relaxVelocity = relaxU;
  o.pimple.relaxPressure = relaxP;
  o.pimple.outerTolerance = 1e-10;
  o.momentumSolver = {1e-12, 0.1, 500};
  o.pressureSolver = {1e-12, 0.01, 500};
  PatchBC in;
  in.type = BoundaryType::FixedVelocity;
  in.velocity = {0.3, 0, 0};
  in.profile = Profile::Parabolic;
  in.parabolicAxes = {false, true, false};
  o.boundaries["inlet"] = in;
  o.boundaries["outlet"].type = BoundaryType::FixedPressure;
  o.boundaries["walls"].type = BoundaryType::Wall;
  o.boundaries["cylinder"].type = BoundaryType::Wall;
  o.boundaries["frontAndBack"].type = BoundaryType::Empty;
  return o;
}

// Pressure at a point (x, y) on the cylinder surface, in the mid-plane of the one-cell-thick mesh.
double surfacePressure(const FluidSolver& fluid, double x, double y) {
  const HexMesh& mesh = fluid.mesh();
  const auto& cyl = mesh.patches()[mesh.patchIndex("cylinder")];
  auto fc = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().faceCentroid);
  return boundaryPressureAt(fluid, "cylinder", {x, y, fc(cyl.start, 2)});
}

struct Solved {
  StepResult step;
  double cd = 0, cl = 0, dp = 0;
  std::vector<double> U, p;
};

Solved solveCylinder(const HexMesh& mesh, const FluidOptions& o) {
  FluidSolver fluid(mesh, o);
  Solved s;
  s.step = fluid.solveStep(0.0, 1.0);
  const auto L = patchLoads(fluid, "cylinder");
  const double q = 0.5 * 0.2 * 0.2 * 0.1 * 0.01;  // rho U^2 D H / 2
  s.cd = L.force[0] / q;
  s.cl = L.force[1] / q;
  s.dp = surfacePressure(fluid, 0.15, 0.2) - surfacePressure(fluid, 0.25, 0.2);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  for (std::size_t i = 0; i < U.extent(0); ++i) {
    for (int j = 0; j < 3; ++j) s.U.push_back(U(i, j));
    s.p.push_back(p(i));
  }
  return s;
}

/// a and b are the same discrete solution: c_D to `tol` relative, the velocities to `tol` of the
/// largest velocity (test::relDiff).
void expectSameSolution(const Solved& a, const Solved& b, double tol) {
  EXPECT_NEAR(a.cd, b.cd, tol * std::abs(b.cd));
  EXPECT_LT(test::relDiff(a.U, b.U), tol);
}

HexMesh readMesh(const std::string& path) {
  if (!std::ifstream(path)) throw std::runtime_error("mesh " + path + " not present");
  return buildHexMesh(readGmsh(path));
}

}  // namespace

TEST(SchaeferTurek, Cylinder2D1DragLiftAndPressureDrop) {
  const HexMesh mesh = readMesh(std::string(MFSI_CASES_DIR) + "/meshes/cylinder_medium.msh");
  const Solved s = solveCylinder(mesh, cylinderOptions(true, 0.9, 1.0));
  std::printf("schaefer-turek 2D-1: c_D = %.4f c_L = %.4f dp = %.4f (%d SIMPLEC iterations, converged %d)\n", s.cd,
              s.cl, s.dp, s.step.outerIterations, int(s.step.converged));
  EXPECT_TRUE(s.step.ok && s.step.converged);
  // Measured on this mesh: c_D 5.574, c_L 0.0107 (inside the published bounds), dp 0.1169 (0.3%
  // below them; surface values are extrapolated from the wall cells).
  EXPECT_TRUE(mfsi::test::near(s.cd, 5.58, mfsi::test::Tol{0.03, 0}, "c_D"));
  EXPECT_TRUE(mfsi::test::near(s.cl, 0.0107, mfsi::test::Tol{0.0015, 0}, "c_L"));
  EXPECT_TRUE(mfsi::test::near(s.dp, 0.1174, mfsi::test::Tol{0.003, 0}, "dp"));
}

// Same relaxation of momentum (which sets rAU, hence the Rhie-Chow interpolation of the converged
// fluxes): SIMPLE (pressure relaxed 0.3) and SIMPLEC (unrelaxed) reach the same discrete solution.
TEST(SchaeferTurek, SimplecConvergesToSimplesSolution) {
  const HexMesh mesh = readMesh(std::string(MFSI_TEST_DATA_DIR) + "/meshes/cylinder_coarse.msh");
  const Solved simple = solveCylinder(mesh, cylinderOptions(false, 0.9, 0.3));
  const Solved simplec = solveCylinder(mesh, cylinderOptions(true, 0.9, 1.0));
  std::printf("coarse cylinder: SIMPLE %d iterations c_D %.10f c_L %.10f; SIMPLEC %d iterations c_D %.10f c_L %.10f\n",
              simple.step.outerIterations, simple.cd, simple.cl, simplec.step.outerIterations, simplec.cd, simplec.cl);
  ASSERT_TRUE(simple.step.ok && simple.step.converged);
  ASSERT_TRUE(simplec.step.ok && simplec.step.converged);
  // Residuals of 1e-10: the two agree to ~1e-8 (measured c_D 5.5609247 in both, fields ~1e-10).
  expectSameSolution(simplec, simple, 1e-7);
  EXPECT_NEAR(simplec.cl, simple.cl, 1e-6 * std::abs(simple.cl));
  // Measured 185 and 157 (OpenFOAM's simpleFoam, SIMPLEC, on this mesh: 185).
  EXPECT_LT(simplec.step.outerIterations, 260);
  EXPECT_LT(simple.step.outerIterations, 260);
  // The published c_D bounds are [5.57, 5.59]; this mesh (1,888 cells) is 0.2 % below them.
  EXPECT_NEAR(simplec.cd, 5.58, 0.04);
}

// The graded Gmsh mesh (tests/data/meshes/cylinder_graded.geo: unstructured quads, 28.5 deg
// maximum non-orthogonality, 1,685 cells), where the non-orthogonal part of SIMPLEC's correction
// matters: both converge to 1e-10 and agree.
TEST(SchaeferTurek, SimplecConvergesOnAGradedUnstructuredMesh) {
  const HexMesh mesh = readMesh(std::string(MFSI_TEST_DATA_DIR) + "/meshes/cylinder_graded.msh");
  const Solved c = solveCylinder(mesh, cylinderOptions(true, 0.9, 1.0));
  const Solved s = solveCylinder(mesh, cylinderOptions(false, 0.9, 0.3));
  std::printf("graded cylinder: SIMPLEC %d iterations, residuals %.2e %.2e, c_D %.10f c_L %.10f; SIMPLE %d, c_D %.10f\n",
              c.step.outerIterations, c.step.finalMomentumResidual, c.step.finalPressureResidual, c.cd, c.cl,
              s.step.outerIterations, s.cd);
  ASSERT_TRUE(c.step.ok && s.step.ok);
  EXPECT_TRUE(c.step.converged);
  EXPECT_TRUE(s.step.converged);
  EXPECT_LT(c.step.outerIterations, 260);  // measured 183 (OpenFOAM's simpleFoam, SIMPLEC: 181)
  expectSameSolution(c, s, 1e-7);
  // Measured 5.614 (OpenFOAM on the same mesh: 5.571); the lift of this coarse unstructured mesh is
  // mesh noise in both codes (ours -0.008, OpenFOAM -0.041), so it is not checked.
  EXPECT_NEAR(c.cd, 5.58, 0.06);
}

// The converged fields do not depend on the under-relaxation: the Rhie-Chow interpolation carries
// the relaxation's own term (FluidSolver::storeRelaxationFlux, on internal and fixed-pressure faces).
// Without it c_D moved by 2.4e-4 between the plain and the diagonally dominant relaxation of the same
// factor; without its outlet part the velocities of U 0.7 and 0.9 differed by 7e-6.
TEST(SchaeferTurek, SteadyAnswerDoesNotDependOnTheRelaxation) {
  const HexMesh mesh = readMesh(std::string(MFSI_TEST_DATA_DIR) + "/meshes/cylinder_coarse.msh");
  const Solved a = solveCylinder(mesh, cylinderOptions(true, 0.9, 1.0));
  const Solved b = solveCylinder(mesh, cylinderOptions(false, 0.7, 0.3));
  std::printf("coarse cylinder: SIMPLEC U 0.9 %d iterations c_D %.10f; SIMPLE U 0.7 p 0.3 %d iterations c_D %.10f\n",
              a.step.outerIterations, a.cd, b.step.outerIterations, b.cd);
  ASSERT_TRUE(a.step.converged && b.step.converged);
  expectSameSolution(a, b, 1e-8);
  EXPECT_NEAR(a.cl, b.cl, 1e-7 * std::abs(a.cl));
}
