// Half-power sine time function f(t) = sin(pi tau / Tp)^p for tau = t mod T < Tp, else 0 (inflow of
// ventricular assist devices): values, input checks, and the flow rate a FlowRate inlet imposes.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/FluidSolver.hpp"
#include "support/Approx.hpp"

#include <cmath>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kPi = 3.14159265358979323846;

HexMesh duct() {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 1}, {6, 3, 3});
  spec.blocks[0].patches = {"left", "right", "side", "side", "side", "side"};
  return buildHexMesh(generateBlockMesh(spec));
}

}  // namespace

TEST(HalfPowerSine, Values) {
  TimeFunction f;
  f.kind = TimeFunction::Kind::HalfPowerSine;
  f.period = 1.0;  // default pulse duration T/2, exponent 1/2
  EXPECT_TRUE(near(f(0.0), 0.0, Tol{1e-15, 0}, "start of pulse"));
  EXPECT_TRUE(near(f(0.125), std::sqrt(std::sqrt(0.5)), Tol{1e-15, 1e-14}, "sqrt(sin(pi/4))"));
  EXPECT_TRUE(near(f(0.25), 1.0, Tol{1e-15, 0}, "peak"));
  EXPECT_TRUE(near(f(0.5), 0.0, Tol{1e-15, 0}, "end of pulse"));
  EXPECT_EQ(f(0.75), 0.0);
  EXPECT_TRUE(near(f(3.125), f(0.125), Tol{1e-14, 0}, "periodic"));
  EXPECT_TRUE(near(f(-0.875), f(0.125), Tol{1e-14, 0}, "periodic for t < 0"));
  EXPECT_TRUE(std::isfinite(f(0.5 - 1e-17)));
  f.period = 0.8;
  f.pulseDuration = 0.3;
  f.exponent = 2.0;
  EXPECT_TRUE(near(f(0.075), 0.5, Tol{1e-15, 1e-14}, "sin(pi/4)^2"));
  EXPECT_TRUE(near(f(0.9), std::pow(std::sin(kPi * 0.1 / 0.3), 2.0), Tol{1e-15, 1e-13}, "second period"));
  EXPECT_EQ(f(0.35), 0.0);
  EXPECT_EQ(f(1.1), 0.0);
}

TEST(HalfPowerSine, SecondPulse) {
  // The pulsatile pump's air port (seed paper): ejection q_e sin^(1/2)(pi t / 0.3) for 0.3 s, then
  // filling q_f sin^(1/2)(pi (t - 0.3) / 0.45), q_f / q_e = -212.68 / 319.02, at 80 beats per minute.
  TimeFunction f;
  f.kind = TimeFunction::Kind::HalfPowerSine;
  f.period = 0.75;
  f.pulseDuration = 0.3;
  f.secondAmplitude = -212.68 / 319.02;
  f.secondDuration = 0.45;
  EXPECT_TRUE(near(f(0.15), 1.0, Tol{1e-15, 0}, "first peak"));
  EXPECT_TRUE(near(f(0.3 + 0.225), -212.68 / 319.02, Tol{1e-15, 1e-14}, "second peak"));
  EXPECT_TRUE(near(f(0.3 + 0.1125), -212.68 / 319.02 * std::sqrt(std::sqrt(0.5)), Tol{1e-15, 1e-14}, "second pulse"));
  EXPECT_TRUE(near(f(0.75 + 0.15), 1.0, Tol{1e-14, 0}, "next beat"));
  // Stroke volumes: int_0^Tp sin^(1/2) = Tp * 0.76275976 (Gamma(3/4) / (sqrt(pi) Gamma(5/4))), so
  // 319.02 * 0.3 * 0.7628 = 73.0 mL out and 212.68 * 0.45 * 0.7628 = 73.0 mL back: the air chamber
  // returns to its volume every beat.
  double out = 0, back = 0;
  const int n = 300000;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * 0.75 / n, v = 319.02 * f(t) * 0.75 / n;
    (v > 0 ? out : back) += v;
  }
  EXPECT_TRUE(near(out, 73.0, Tol{0, 2e-3}, "ejected volume (mL)"));
  EXPECT_TRUE(near(-back, out, Tol{0, 1e-4}, "filled volume = ejected volume"));
}

TEST(HalfPowerSine, InvalidParametersAreInputErrors) {
  HexMesh mesh = duct();
  FluidOptions o;
  o.boundaries["left"].type = BoundaryType::FlowRate;
  o.boundaries["left"].flowRate = 1.0;
  o.boundaries["left"].timeFunction.kind = TimeFunction::Kind::HalfPowerSine;
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  o.boundaries["side"].type = BoundaryType::Wall;
  EXPECT_NO_THROW(FluidSolver(mesh, o));
  o.boundaries["left"].timeFunction.pulseDuration = 1.5;  // longer than the period
  EXPECT_THROW(FluidSolver(mesh, o), InputError);
  o.boundaries["left"].timeFunction.pulseDuration = 0.5;
  o.boundaries["left"].timeFunction.exponent = 0.0;
  EXPECT_THROW(FluidSolver(mesh, o), InputError);
}

TEST(HalfPowerSine, FlowRateInletFollowsThePulse) {
  const double Q = 0.3, T = 0.8, Tp = 0.3, dt = 0.05;
  HexMesh mesh = duct();
  FluidOptions o;
  o.viscosity = 0.05;
  o.timeScheme = TimeScheme::BDF2;
  PatchBC in;
  in.type = BoundaryType::FlowRate;
  in.flowRate = Q;
  in.profile = Profile::Parabolic;
  in.parabolicAxes = {false, true, true};
  in.timeFunction.kind = TimeFunction::Kind::HalfPowerSine;
  in.timeFunction.period = T;
  in.timeFunction.pulseDuration = Tp;
  o.boundaries["left"] = in;
  o.boundaries["right"].type = BoundaryType::FixedPressure;
  o.boundaries["side"].type = BoundaryType::Wall;
  FluidSolver fluid(mesh, o);
  const auto& left = mesh.patches()[mesh.patchIndex("left")];
  const auto& right = mesh.patches()[mesh.patchIndex("right")];
  int nonZero = 0, zero = 0;
  for (int s = 0; s < 20; ++s) {  // t + dt from 0.05 to 1.0: pulse, rest, start of the next pulse
    const double t = s * dt;
    ASSERT_TRUE(fluid.solveStep(t, dt).ok);
    auto phi = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceFlux());
    double qin = 0, qout = 0;
    for (int f = left.start; f < left.start + left.size; ++f) qin -= phi(f);
    for (int f = right.start; f < right.start + right.size; ++f) qout += phi(f);
    const double tau = std::fmod(t + dt, T);
    const double expected = tau < Tp ? Q * std::sqrt(std::sin(kPi * tau / Tp)) : 0.0;
    EXPECT_TRUE(near(qin, expected, Tol{1e-12, 1e-12}, "inflow")) << "t = " << t + dt;
    EXPECT_TRUE(near(qout, expected, Tol{1e-8, 1e-7}, "outflow (continuity)")) << "t = " << t + dt;
    (expected > 0.1 * Q ? nonZero : zero) += 1;
  }
  EXPECT_GE(nonZero, 6);
  EXPECT_GE(zero, 8);
}
