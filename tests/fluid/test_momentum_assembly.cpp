// The fused momentum assembly (one pass per cell) against the face-coefficient path it replaces on
// orthogonal meshes: same fields after several PISO steps with every boundary kind it handles, for
// linear and upwind convection and both time schemes. Also: the velocity gradient the solver skips
// on such meshes is still served, on request, for the loads.
#include "fluid/FluidSolver.hpp"
#include "fluid/Gradient.hpp"
#include "support/Approx.hpp"
#include "support/FluidCases.hpp"

#include <algorithm>
#include <cmath>
#include <string>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

FluidOptions options(ConvectionScheme conv, TimeScheme time, bool fused) {
  FluidOptions o = test::channelFlowOptions(time);
  o.convection = conv;
  o.fusedMomentumAssembly = fused;
  o.pimple.relaxVelocity = 0.9;
  return o;
}

struct Fields {
  Kokkos::View<real* [3], HostSpace> U;
  Kokkos::View<real*, HostSpace> p;
};

Fields run(const HexMesh& mesh, const FluidOptions& o, int steps) {
  FluidSolver fluid(mesh, o);
  for (int s = 0; s < steps; ++s) EXPECT_TRUE(fluid.solveStep(s * 0.05, 0.05).ok);
  Fields f{Kokkos::View<real* [3], HostSpace>("test::U", mesh.nCells()),
           Kokkos::View<real*, HostSpace>("test::p", mesh.nCells())};
  Kokkos::deep_copy(f.U, fluid.velocity());
  Kokkos::deep_copy(f.p, fluid.pressure());
  return f;
}

}  // namespace

TEST(MomentumAssembly, FusedPassEqualsTheFaceCoefficientPath) {
  for (bool twoD : {false, true}) {
    const HexMesh mesh = test::channelBoxMesh(twoD);
    for (ConvectionScheme conv : {ConvectionScheme::Linear, ConvectionScheme::Upwind}) {
      for (TimeScheme time : {TimeScheme::Euler, TimeScheme::BDF2}) {
        const std::string what = std::string(twoD ? "2D" : "3D") + (conv == ConvectionScheme::Linear ? " linear" : " upwind") +
                                 (time == TimeScheme::Euler ? " Euler" : " BDF2");
        const Fields a = run(mesh, options(conv, time, true), 4);
        const Fields b = run(mesh, options(conv, time, false), 4);
        double du = 0, dp = 0, umax = 0, pmax = 0;
        for (int c = 0; c < mesh.nCells(); ++c) {
          for (int j = 0; j < 3; ++j) {
            du = std::max(du, std::abs(a.U(c, j) - b.U(c, j)));
            umax = std::max(umax, std::abs(b.U(c, j)));
          }
          dp = std::max(dp, std::abs(a.p(c) - b.p(c)));
          pmax = std::max(pmax, std::abs(b.p(c)));
        }
        // The flow is not trivial (inflow 1, lid -0.5, body force, outlet pressure 0.5)...
        ASSERT_GT(umax, 0.5) << what;
        ASSERT_GT(pmax, 0.1) << what;
        // ...and both paths give it to round-off (same matrix and source, summed in the same order).
        EXPECT_LE(du, 1e-12 * umax) << what;
        EXPECT_LE(dp, 1e-12 * pmax) << what;
      }
    }
  }
}

TEST(MomentumAssembly, VelocityGradientIsServedWhenTheSolverSkippedIt) {
  const HexMesh mesh = test::channelBoxMesh(false);
  FluidSolver fluid(mesh, options(ConvectionScheme::Linear, TimeScheme::Euler, true));
  for (int s = 0; s < 2; ++s) ASSERT_TRUE(fluid.solveStep(s * 0.05, 0.05).ok);
  Tensor3View expected("test::gradU", mesh.nCells());
  cellGradient(ExecSpace(), fluid.options().gradient, mesh, fluid.geometry(), fluid.faceData(), fluid.velocity(),
               fluid.boundaryVelocity(), expected);
  auto he = Kokkos::create_mirror_view_and_copy(HostSpace(), expected);
  auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocityGradient());
  double gmax = 0, diff = 0;
  for (int c = 0; c < mesh.nCells(); ++c)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        gmax = std::max(gmax, std::abs(he(c, i, j)));
        diff = std::max(diff, std::abs(hg(c, i, j) - he(c, i, j)));
      }
  ASSERT_GT(gmax, 0.5);  // a sheared flow, not the zero-initialised array
  EXPECT_LE(diff, 1e-12 * gmax);  // the solver's stencil form of the same gradient
}
