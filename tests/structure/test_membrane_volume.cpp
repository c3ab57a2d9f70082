// The volume constraint of the membrane step (a membrane closing a region of incompressible
// fluid). On a closed sphere every node moves along its reference normal, so a uniform stretch
// lambda is admissible and scaling every position by lambda scales the volume function by lambda^3
// exactly: the target (lambda^3 - 1) V0 is then met by the uniformly stretched sphere, and the
// multiplier must be the St. Venant-Kirchhoff inflation pressure p = 2 h S / (lambda R0),
// S = E (lambda^2 - 1) / (2 (1 - nu)) (the inflation test's exact solution; the mass is made
// negligible). The same step under that pressure without the constraint must land on the same
// displacement.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <cmath>

using namespace mfsi;

namespace {

struct Sphere {
  MembraneMesh mesh;
  MembraneBoundary bc;
  MembraneOptions opt;
};

Sphere sphere(int n) {
  MembraneSphereSpec sph;
  sph.radius = 1;
  sph.n = n;
  Sphere s{buildMembraneMesh(generateSphereMesh(sph)), {}, {}};
  for (lid_t i = 0; i < s.mesh.nNodes(); ++i) s.bc.normalNodes.push_back(i);
  s.opt.material = {1e6, 0.3, 1e-3, 1e-6, 0};  // E, nu, h, rho (negligible inertia), T0
  s.opt.tolerance = 1e-10;
  s.opt.newton.maxIterations = 60;
  return s;
}

RealView scaledPositions(const MembraneMesh& mesh, double lambda) {
  RealView u("u", 3 * mesh.nNodes());
  auto h = Kokkos::create_mirror_view(u);
  for (lid_t i = 0; i < mesh.nNodes(); ++i)
    for (int k = 0; k < 3; ++k) h(3 * i + k) = (lambda - 1) * mesh.hostPoints()[i][k];
  Kokkos::deep_copy(u, h);
  return u;
}

std::vector<double> host(const ConstRealView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.extent(0));
}

}  // namespace

TEST(MembraneVolume, ConstrainedStepFindsTheInflationPressure) {
  const double lambda = 1.5, E = 1e6, nu = 0.3, h = 1e-3;
  const double pExact = 2 * h * E * 0.5 * (lambda * lambda - 1) / (1 - nu) / lambda;
  Sphere s = sphere(16);
  // Generalized-alpha (af = 1/3): the multiplier enters the step's residual weighted by 1 - af,
  // which the compliance below must not carry (with Newmark's af = 0 it could not be told).
  s.opt.dynamics.integrator = MembraneTimeIntegrator::GeneralizedAlpha;
  s.opt.dynamics.rhoInfinity = 0.5;
  MembraneSolver solver(s.mesh, s.opt, s.bc);
  const double target = solver.enclosedVolume(scaledPositions(s.mesh, lambda));
  EXPECT_NEAR(target, (lambda * lambda * lambda - 1) * 4.0 / 3.0 * M_PI, 0.02 * target) << "a sphere's volume";
  MembraneVolumeConstraint& vc = solver.volumeConstraint();
  vc.active = true;
  vc.target = target;
  const MembraneSolveReport rep = solver.solveStep(1.0);
  ASSERT_TRUE(rep.converged) << "residual " << rep.relativeResidual << " after " << rep.iterations;
  const double volume = solver.enclosedVolume(solver.trialDisplacement());
  std::printf("constrained step: %d Newton iterations, volume %.15g (target %.15g), multiplier %.6g Pa (exact %.6g)\n",
              rep.iterations, volume, target, vc.lambda, pExact);
  EXPECT_LE(std::abs(volume - target), 1e-10 * target) << "the volume constraint holds";
  // The discrete sphere's stretch is within 0.6 % of uniform at n = 16 (the inflation test).
  EXPECT_NEAR(vc.lambda, pExact, 0.01 * pExact) << "the multiplier is the inflation pressure";
  // The volume's response to the multiplier: with negligible mass the step's matrix is (1 - af) K
  // and b solves it for (1 - af) g, so g.b = g K^-1 g is dV/dp of the inflated sphere,
  // dV/dlambda / dp/dlambda = 4 pi lambda^2 (1 - nu) / (h E (1 + 1 / lambda^2)) (a compliance
  // scaled by 1 - af would be 2/3 of it).
  const double compliance = 4 * M_PI * lambda * lambda * (1 - nu) / (h * E * (1 + 1 / (lambda * lambda)));
  std::printf("volume compliance %.6g m^3/Pa (the sphere's %.6g)\n", vc.compliance, compliance);
  EXPECT_NEAR(vc.compliance, compliance, 0.02 * compliance);

  // Unconstrained, under the multiplier as a pressure: the same step, the same displacement.
  MembraneLoads loads;
  loads.pressure = vc.lambda;
  // Zero at t = 0 as the multiplier was: the same initial acceleration (M a = R at rest).
  loads.pressureTime = [](real t) { return t; };
  MembraneSolver free(s.mesh, s.opt, s.bc, loads);
  const MembraneSolveReport rep2 = free.solveStep(1.0);
  ASSERT_TRUE(rep2.converged);
  const std::vector<double> a = host(solver.trialDisplacement()), b = host(free.trialDisplacement());
  double diff = 0, ref = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::abs(a[i] - b[i]));
    ref = std::max(ref, std::abs(a[i]));
  }
  EXPECT_LT(diff, 1e-7 * ref) << "the multiplier is the pressure that makes the same step";
  // A wrong sign of the constraint would shrink the sphere instead.
  EXPECT_GT(a[0] * s.mesh.hostPoints()[0][0] + a[1] * s.mesh.hostPoints()[0][1] + a[2] * s.mesh.hostPoints()[0][2], 0);
}

TEST(MembraneVolume, ProjectionMeetsTheTargetAndKeepsConstrainedDirections) {
  Sphere s = sphere(8);
  MembraneSolver solver(s.mesh, s.opt, s.bc);
  MembraneVolumeConstraint& vc = solver.volumeConstraint();
  vc.active = true;
  vc.target = solver.enclosedVolume(scaledPositions(s.mesh, 1.2));
  // A non-uniform iterate with the wrong volume: 1.25 on one half, 1.1 on the other.
  RealView u("u", 3 * s.mesh.nNodes());
  {
    auto hu = Kokkos::create_mirror_view(u);
    for (lid_t i = 0; i < s.mesh.nNodes(); ++i) {
      const auto& X = s.mesh.hostPoints()[i];
      const double f = X[2] > 0 ? 0.25 : 0.1;
      for (int k = 0; k < 3; ++k) hu(3 * i + k) = f * X[k];
    }
    Kokkos::deep_copy(u, hu);
  }
  RealView u0("u0", u.extent(0));
  Kokkos::deep_copy(u0, u);
  const double before = solver.enclosedVolume(u);
  const double move = solver.projectOntoVolume(u);
  const double after = solver.enclosedVolume(u);
  std::printf("projection: volume %.12g -> %.12g (target %.12g), largest move %.3g\n", before, after, vc.target, move);
  EXPECT_GT(std::abs(before - vc.target), 1e-3 * vc.target);
  EXPECT_LE(std::abs(after - vc.target), 1e-10 * vc.target);
  EXPECT_GT(move, 0);
  EXPECT_LT(move, 0.2) << "a small correction, not a new shape";
  // The correction lies in the constrained directions (every node along its reference normal).
  RealView d("d", u.extent(0)), pd("pd", u.extent(0));
  Kokkos::deep_copy(d, u);
  blas::axpy(ExecSpace(), static_cast<lid_t>(u.extent(0)), -1.0, u0, d);
  projectConstraints(ExecSpace(), solver.constraints(), d, pd);
  const std::vector<double> hd = host(d), hpd = host(pd);
  double off = 0, size = 0;
  for (std::size_t i = 0; i < hd.size(); ++i) {
    off = std::max(off, std::abs(hd[i] - hpd[i]));
    size = std::max(size, std::abs(hd[i]));
  }
  EXPECT_GT(size, 1e-3);
  EXPECT_LT(off, 1e-14 * size) << "the projection moved a node off its constrained direction";
}

TEST(MembraneVolume, GeneralizedAlphaMultiplierIsTheStepsNotTheStartGuess) {
  // Generalized-alpha weighs the loads of t_n by alpha_f: the multiplier of t_n must enter there,
  // never the iterate's starting guess, or the step's answer depends on where Newton started.
  Sphere s = sphere(8);
  s.opt.material.density = 1;  // inertia matters: the step is dynamic
  s.opt.dynamics.integrator = MembraneTimeIntegrator::GeneralizedAlpha;
  s.opt.dynamics.rhoInfinity = 0.5;
  std::vector<double> lambdas;
  for (double guess : {0.0, 1000.0}) {
    MembraneSolver solver(s.mesh, s.opt, s.bc);
    MembraneVolumeConstraint& vc = solver.volumeConstraint();
    vc.active = true;
    vc.target = solver.enclosedVolume(scaledPositions(s.mesh, 1.1));
    ASSERT_TRUE(solver.step(0.01).converged);
    vc.target = solver.enclosedVolume(scaledPositions(s.mesh, 1.2));
    vc.lambda = guess;
    const MembraneSolveReport rep = solver.solveStep(0.01);
    ASSERT_TRUE(rep.converged) << "guess " << guess;
    lambdas.push_back(vc.lambda);
  }
  std::printf("second step's multiplier from the guesses 0 and 1000 Pa: %.15g, %.15g\n", lambdas[0], lambdas[1]);
  EXPECT_NEAR(lambdas[0], lambdas[1], 1e-9 * std::abs(lambdas[0]));
}
