// The fused per-step kernels of the fluid solver (pressure matrix, pressure source flux, end-of-step
// pass, momentum row functor, pressure gradient with its boundary pressures) against the per-face
// reference paths they replace, on the configurations those paths branch on; the time-level
// bookkeeping that skips copies (static or intermittently moving meshes, Euler vs BDF2, repeated
// beginStep); and that the per-face arrays the fused paths no longer need are not allocated.
#include "fluid/FluidSolver.hpp"
#include "support/Approx.hpp"
#include "support/FluidCases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <set>
#include <string>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

using test::channelBoxMesh;
using test::channelFlowOptions;
using test::cubeCavityMesh;

FluidOptions cavityOptions() {
  FluidOptions o;
  o.viscosity = 0.01;
  o.timeScheme = TimeScheme::Euler;
  o.pimple.nOuterCorrectors = 1;
  o.pimple.nCorrectors = 2;
  o.momentumSolver = {1e-12, 0.0, 500};
  o.pressureSolver = {1e-12, 0.0, 500};
  o.boundaries["lid"].type = BoundaryType::Wall;
  o.boundaries["lid"].velocity = {1.0, 0.0, 0.0};
  return o;
}

struct Fields {
  Kokkos::View<real* [3], HostSpace> U;
  Kokkos::View<real*, HostSpace> p, phi;
};

/// Host copies (not mirrors, which alias the solver's arrays on host backends).
Fields fields(const FluidSolver& fluid) {
  Fields f{Kokkos::View<real* [3], HostSpace>("test::U", fluid.velocity().extent(0)),
           Kokkos::View<real*, HostSpace>("test::p", fluid.pressure().extent(0)),
           Kokkos::View<real*, HostSpace>("test::phi", fluid.faceFlux().extent(0))};
  Kokkos::deep_copy(f.U, fluid.velocity());
  Kokkos::deep_copy(f.p, fluid.pressure());
  Kokkos::deep_copy(f.phi, fluid.faceFlux());
  return f;
}

Fields run(const HexMesh& mesh, const FluidOptions& o, int steps, double dt) {
  FluidSolver fluid(mesh, o);
  for (int s = 0; s < steps; ++s) EXPECT_TRUE(fluid.solveStep(s * dt, dt).ok);
  return fields(fluid);
}

/// Largest |a - b| relative to the largest |b|, over U, p and the face fluxes; also checks the
/// flow is not trivial.
void expectSame(const Fields& a, const Fields& b, const std::string& what, double tol = 1e-12) {
  double du = 0, umax = 0, dp = 0, pmax = 0, df = 0, fmax = 0;
  for (std::size_t c = 0; c < b.p.extent(0); ++c) {
    for (int j = 0; j < 3; ++j) {
      du = std::max(du, std::abs(a.U(c, j) - b.U(c, j)));
      umax = std::max(umax, std::abs(b.U(c, j)));
    }
    dp = std::max(dp, std::abs(a.p(c) - b.p(c)));
    pmax = std::max(pmax, std::abs(b.p(c)));
  }
  for (std::size_t f = 0; f < b.phi.extent(0); ++f) {
    df = std::max(df, std::abs(a.phi(f) - b.phi(f)));
    fmax = std::max(fmax, std::abs(b.phi(f)));
  }
  ASSERT_GT(umax, 0.05) << what;
  ASSERT_GT(pmax, 1e-3) << what;
  EXPECT_LE(du, tol * umax) << what;
  EXPECT_LE(dp, tol * pmax) << what;
  EXPECT_LE(df, tol * fmax) << what;
}

// Interior nodes of the channel wobble; boundary nodes stay.
MeshMotion wobble(const HexMesh& mesh) {
  auto ref = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  const int nn = mesh.nNodes();
  return [ref, nn](real t, const Real3View& pts) {
    auto h = Kokkos::create_mirror_view(pts);
    for (int n = 0; n < nn; ++n) {
      const double x = ref(n, 0), y = ref(n, 1), z = ref(n, 2);
      const bool inside = x > 1e-9 && x < 2 - 1e-9 && y > 1e-9 && y < 1 - 1e-9 && z > 1e-9 && z < 0.6 - 1e-9;
      h(n, 0) = x + (inside ? 0.03 * std::sin(3 * y + 5 * t) : 0.0);
      h(n, 1) = y + (inside ? 0.02 * std::sin(2 * x + 4 * t) : 0.0);
      h(n, 2) = z;
    }
    Kokkos::deep_copy(pts, h);
  };
}

/// `steps` steps of dt of the solvers a and b, each on its own copy of `mesh`, both meshes moved by
/// `motion` in the steps s where moves(s).
template <class Moves>
void stepWithMotion(FluidSolver& a, FluidSolver& b, const HexMesh& mesh, const MeshMotion& motion, int steps, double dt,
                    const Moves& moves) {
  for (int s = 0; s < steps; ++s) {
    for (FluidSolver* f : {&a, &b}) {
      f->beginStep(s * dt, dt);
      if (moves(s)) {
        Real3View pts("test::points", mesh.nNodes());
        motion((s + 1) * dt, pts);
        f->moveMesh(pts);
      }
      ASSERT_TRUE(f->solve().ok) << "step " << s;
    }
  }
}

std::set<std::string>& allocations() {
  static std::set<std::string> labels;
  return labels;
}

void recordAllocation(const Kokkos::Profiling::SpaceHandle, const char* label, const void*, uint64_t) {
  allocations().insert(label);
}

}  // namespace

TEST(FusedKernels, FusedPathsEqualTheFacePaths) {
  // Each pair differs only in fusedMomentumAssembly (which switches every fused pass); the flow
  // configurations cover the branches of those passes: a pinned pressure level, artificial
  // compressibility (cell diagonal and old pressures), pressure relaxation, non-orthogonal
  // correctors on an orthogonal mesh, a resistance outlet (boundary pressure changing every
  // corrector), Euler and BDF2 (second old level read or skipped).
  const HexMesh box = cubeCavityMesh(6);
  const HexMesh chan = channelBoxMesh();
  struct Case {
    std::string name;
    const HexMesh* mesh;
    FluidOptions o;
  };
  std::vector<Case> cases;
  cases.push_back({"cavity", &box, cavityOptions()});
  {
    FluidOptions o = cavityOptions();
    o.artificialCompressibility.soundSpeed = 5.0;
    o.timeScheme = TimeScheme::BDF2;
    cases.push_back({"cavity compressible BDF2", &box, o});
  }
  {
    FluidOptions o = cavityOptions();
    o.pimple.relaxPressure = 0.7;
    o.pimple.nNonOrthogonalCorrectors = 1;
    cases.push_back({"cavity relaxed", &box, o});
  }
  cases.push_back({"channel Euler", &chan, channelFlowOptions(TimeScheme::Euler)});
  cases.push_back({"channel BDF2", &chan, channelFlowOptions(TimeScheme::BDF2)});
  {
    FluidOptions o = channelFlowOptions(TimeScheme::BDF2);
    o.boundaries["outlet"].type = BoundaryType::Resistance;
    o.boundaries["outlet"].resistance = 2.0;
    cases.push_back({"channel resistance", &chan, o});
  }
  for (auto& c : cases) {
    FluidOptions unfused = c.o;
    unfused.fusedMomentumAssembly = false;
    expectSame(run(*c.mesh, c.o, 5, 0.05), run(*c.mesh, unfused, 5, 0.05), c.name);
  }
}

/// Boundary-face pressures of a solver (host copy).
Kokkos::View<real*, HostSpace> boundaryPressures(const FluidSolver& fluid) {
  Kokkos::View<real*, HostSpace> pb("test::pb", fluid.boundaryPressure().extent(0));
  Kokkos::deep_copy(pb, fluid.boundaryPressure());
  return pb;
}

/// Largest |a - b| over the boundary pressures relative to the largest |b|, which must not be 0.
double boundaryPressureDifference(const FluidSolver& a, const FluidSolver& b) {
  const auto pa = boundaryPressures(a), pbv = boundaryPressures(b);
  double d = 0, m = 0;
  for (std::size_t i = 0; i < pbv.extent(0); ++i) {
    d = std::max(d, std::abs(pa(i) - pbv(i)));
    m = std::max(m, std::abs(pbv(i)));
  }
  EXPECT_GT(m, 1e-3);
  return d / m;
}

TEST(FusedKernels, PressureGradientPassEqualsTheSeparateKernels) {
  // The one-pass pressure gradient (boundary pressures formed inside it, the extrapolated wall
  // pressures' second sweep per cell), the skipped face fluxes of intermediate correctors, the
  // final fluxes formed with the correction fluxes after the velocity correction, and the
  // pressure matrix from the stored face coefficients, against the separate kernels: both
  // wall-pressure modes, three correctors (a middle one skips its fluxes), a 2D channel with
  // empty faces and a fixed-pressure outlet, and pressure relaxation (the gradient of the relaxed
  // pressure; the final fluxes then stay in the corrector).
  const HexMesh box = cubeCavityMesh(6);
  const HexMesh chan2d = channelBoxMesh(/*twoD=*/true);
  struct Case {
    std::string name;
    const HexMesh* mesh;
    FluidOptions o;
  };
  std::vector<Case> cases;
  for (WallPressure wp : {WallPressure::Extrapolated, WallPressure::ZeroGradient}) {
    const std::string tag = wp == WallPressure::Extrapolated ? " extrapolated" : " zero-gradient";
    FluidOptions o = cavityOptions();
    o.wallPressure = wp;
    o.pimple.nCorrectors = 3;
    cases.push_back({"cavity 3 correctors" + tag, &box, o});
    FluidOptions c = channelFlowOptions(TimeScheme::Euler);
    c.wallPressure = wp;
    c.pimple.relaxPressure = 0.8;
    cases.push_back({"2D channel relaxed" + tag, &chan2d, c});
  }
  for (auto& c : cases) {
    FluidOptions unfused = c.o;
    unfused.fusedMomentumAssembly = false;
    FluidSolver a(*c.mesh, c.o), b(*c.mesh, unfused);
    for (int s = 0; s < 5; ++s) {
      ASSERT_TRUE(a.solveStep(s * 0.05, 0.05).ok) << c.name;
      ASSERT_TRUE(b.solveStep(s * 0.05, 0.05).ok) << c.name;
    }
    expectSame(fields(a), fields(b), c.name);
    EXPECT_LE(boundaryPressureDifference(a, b), 1e-12) << c.name;
  }
}

TEST(FusedKernels, PressureGradientPassOnAMovingMesh) {
  // The same on a wobbling (non-orthogonal, moving) channel mesh, whose walls extrapolate the
  // pressure along tilted cell-to-face vectors and whose pressure matrix takes the inline face
  // coefficients (the source flux takes the face path there): fields and boundary pressures to
  // 1e-12 after steps with and without motion.
  HexMesh meshA = channelBoxMesh(), meshB = channelBoxMesh();
  FluidOptions o = channelFlowOptions(TimeScheme::Euler);
  o.pimple.nOuterCorrectors = 1;
  o.pimple.nCorrectors = 3;
  FluidOptions unfused = o;
  unfused.fusedMomentumAssembly = false;
  FluidSolver a(meshA, o), b(meshB, unfused);
  ASSERT_NO_FATAL_FAILURE(stepWithMotion(a, b, meshA, wobble(meshA), 5, 0.05, [](int s) { return s != 2; }));
  expectSame(fields(a), fields(b), "moving channel");
  EXPECT_LE(boundaryPressureDifference(a, b), 1e-12);
}

TEST(FusedKernels, MovingMeshPathsEqualTheFacePaths) {
  // On a moving (hence non-orthogonal) mesh the pressure matrix and end-of-step passes stay fused
  // while the source flux and momentum take the face paths; motion in some steps only exercises
  // the skipped copies of volumes, positions and swept volumes.
  for (TimeScheme time : {TimeScheme::Euler, TimeScheme::BDF2}) {
    HexMesh meshA = channelBoxMesh(), meshB = channelBoxMesh();
    FluidOptions o = channelFlowOptions(time);
    o.pimple.nNonOrthogonalCorrectors = 1;
    FluidOptions unfused = o;
    unfused.fusedMomentumAssembly = false;
    FluidSolver a(meshA, o), b(meshB, unfused);
    ASSERT_NO_FATAL_FAILURE(
        stepWithMotion(a, b, meshA, wobble(meshA), 7, 0.05, [](int s) { return s == 1 || s == 2 || s == 5; }));
    expectSame(fields(a), fields(b), time == TimeScheme::Euler ? "moving Euler" : "moving BDF2");
  }
}

TEST(FusedKernels, UniformFlowStaysUniformWithIntermittentMotion) {
  // Space conservation when the mesh moves in some steps only: the old volumes, positions and
  // swept volumes that beginStep now copies only after motion must still be those of the step.
  // A stale V0 or swept volume breaks the balance and the uniform flow with it.
  for (TimeScheme time : {TimeScheme::Euler, TimeScheme::BDF2}) {
    HexMesh mesh = channelBoxMesh();
    const Vec3 U0{1.0, 0.5, -0.25};
    FluidOptions o;
    o.viscosity = 0.05;
    o.timeScheme = time;
    o.initialVelocity = U0;
    o.pimple.nOuterCorrectors = 2;
    o.pimple.nCorrectors = 2;
    o.pimple.nNonOrthogonalCorrectors = 1;
    o.momentumSolver = {1e-13, 0.0, 500};
    o.pressureSolver = {1e-13, 0.0, 500};
    for (const char* name : {"inlet", "bottom", "lid", "sides"}) {
      o.boundaries[name].type = BoundaryType::FixedVelocity;
      o.boundaries[name].velocity = U0;
    }
    o.boundaries["outlet"].type = BoundaryType::FixedPressure;
    FluidSolver fluid(mesh, o);
    const auto motion = wobble(mesh);
    double maxDev = 0, maxMeshFlux = 0;
    for (int s = 0; s < 8; ++s) {
      fluid.beginStep(s * 0.05, 0.05);
      if (s % 3 == 1) {
        Real3View pts("test::points", mesh.nNodes());
        motion((s + 1) * 0.05, pts);
        fluid.moveMesh(pts);
      }
      ASSERT_TRUE(fluid.solve().ok);
      auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
      for (int c = 0; c < mesh.nCells(); ++c)
        for (int k = 0; k < 3; ++k) maxDev = std::max(maxDev, std::abs(U(c, k) - U0[k]));
      auto mp = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.meshFlux());
      for (int f = 0; f < mesh.nFaces(); ++f) maxMeshFlux = std::max(maxMeshFlux, std::abs(mp(f)));
    }
    EXPECT_GT(maxMeshFlux, 1e-3) << toString(time);  // the mesh really moves
    EXPECT_LT(maxDev, 1e-10) << toString(time);
  }
}

TEST(FusedKernels, RepeatedBeginStepChangesNothingWithEuler) {
  // With Euler a second beginStep(t, dt) before solve() copies the same time levels again: no
  // effect. The correction fluxes are handed on between arrays instead of copied, so the second
  // call must find the latest ones where the first left them.
  const HexMesh mesh = cubeCavityMesh(6);
  FluidOptions o = cavityOptions();
  // The extrapolated momentum guess reads the step before the last one, which a repeated
  // beginStep does replace: off here, the time levels are what is compared.
  o.pimple.extrapolateGuess = false;
  FluidSolver once(mesh, o), twice(mesh, o);
  const double dt = 0.05;
  for (int s = 0; s < 4; ++s) {
    ASSERT_TRUE(once.solveStep(s * dt, dt).ok);
    twice.beginStep(s * dt, dt);
    twice.beginStep(s * dt, dt);
    ASSERT_TRUE(twice.solve().ok);
  }
  expectSame(fields(twice), fields(once), "repeated beginStep", 0.0);
}

TEST(FusedKernels, FusedPathsAllocateNoPerFaceCoefficients) {
  // The fused passes never read the per-face coefficient arrays (8 doubles per face for the two
  // matrices), the explicit momentum face fluxes (3) or phiHbyA (1): they are allocated on first
  // use by the face paths only.
  const HexMesh mesh = cubeCavityMesh(4);
  const std::vector<std::string> lazy = {"mfsi::fluid::momentum::face::ownerDiag", "mfsi::fluid::pressure::face::upper",
                                         "mfsi::fluid::momentum::faceFlux", "mfsi::fluid::phiHbyA"};
  for (bool fused : {true, false}) {
    FluidOptions o = cavityOptions();
    o.fusedMomentumAssembly = fused;
    allocations().clear();
    Kokkos::Tools::Experimental::set_allocate_data_callback(&recordAllocation);
    {
      FluidSolver fluid(mesh, o);
      for (int s = 0; s < 2; ++s) ASSERT_TRUE(fluid.solveStep(s * 0.05, 0.05).ok);
    }
    Kokkos::Tools::Experimental::set_allocate_data_callback(nullptr);
    if (allocations().empty()) GTEST_SKIP() << "this Kokkos build does not report allocations to tool callbacks";
    ASSERT_GT(allocations().count("mfsi::fluid::U"), 0u);  // the callback saw the solver's views
    for (const auto& label : lazy)
      EXPECT_EQ(allocations().count(label), fused ? 0u : 1u) << label << (fused ? " (fused)" : " (face paths)");
  }
}

TEST(FusedKernels, MomentumAssemblyFormsTheJacobiInverse) {
  // The fused momentum assembly writes the Jacobi inverse diagonal the momentum solve uses
  // (invertDiagonal's formula); the face path leaves it to invertDiagonal. Same preconditioner,
  // so every momentum solve takes the same iterations and ends on the same residual, with
  // OpenFOAM-like tolerances where a different Jacobi would change the counts.
  const HexMesh mesh = cubeCavityMesh(10);
  FluidOptions fused = cavityOptions(), unfused = cavityOptions();
  fused.momentumSolver = unfused.momentumSolver = {1e-5, 0.0, 500};
  fused.pressureSolver = unfused.pressureSolver = {1e-6, 0.05, 500};
  unfused.fusedMomentumAssembly = false;
  FluidSolver a(mesh, fused), b(mesh, unfused);
  const double dt = 0.02;
  for (int s = 0; s < 5; ++s) {
    const StepResult ra = a.solveStep(s * dt, dt), rb = b.solveStep(s * dt, dt);
    ASSERT_TRUE(ra.ok && rb.ok);
    EXPECT_EQ(ra.momentumIterations, rb.momentumIterations) << "step " << s;
    EXPECT_EQ(ra.finalMomentumResidual, rb.finalMomentumResidual) << "step " << s;
  }
}
