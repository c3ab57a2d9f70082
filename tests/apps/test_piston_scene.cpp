// Strong added mass with an exact answer (cases/piston.yaml): a rigid piston of mass m on a spring k
// closes a duct of water (length L, cross-section A) whose far end is open; the side walls slip, so
// the column moves as a plug and the piston oscillates at omega = sqrt(k / (m + rho A L)).
//  - implicit coupling (IQN-ILS) meets that frequency within 1 % for m / m_a from 10 down to 0.01;
//  - the explicit (staggered) scheme diverges once m_a / m is large, and is stable when it is small;
//  - Aitken meets the same answer when its omega may fall to the secant of the -m_a/m map;
//  - coupling input errors about bodies name the key.
#include "support/SceneErrors.hpp"

#include "coupling/Module.hpp"
#include "coupling/Simulation.hpp"
#include "core/Error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

const std::string kScene = std::string(MFSI_CASES_DIR) + "/piston.yaml";
constexpr double kAddedMass = 1000.0 * 0.1 * 0.1 * 1.0;  // rho A L of the scene
constexpr double kStiffness = 1000.0;

struct PistonRun {
  std::string status = "ok";  ///< ok | diverged (the run threw DivergenceError)
  std::string error;
  mfsi::RunResult result;
  std::vector<double> t, x;  ///< piston x (bodies.csv) per committed step, from t = 0
  long long steps() const { return static_cast<long long>(t.size()) - 1; }
};

PistonRun run(const std::vector<std::string>& sets, const std::string& tag) {
  const std::string dir = ::testing::TempDir() + "/piston_" + tag;
  std::filesystem::create_directories(dir);
  PistonRun r;
  {
    auto cfg = mfsi::SceneConfig::load(kScene, mfsi::sceneSchema(), sets);
    mfsi::Simulation sim(cfg);  // closes bodies.csv when it goes
    try {
      r.result = sim.run(dir, false);
    } catch (const mfsi::DivergenceError& e) {
      r.status = "diverged";
      r.error = e.what();
    }
  }
  std::ifstream in(dir + "/bodies.csv");
  std::string line;
  std::getline(in, line);  // header: time,body,x,...
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string time, body, x;
    std::getline(s, time, ',');
    std::getline(s, body, ',');
    std::getline(s, x, ',');
    r.t.push_back(std::stod(time));
    r.x.push_back(std::stod(x));
  }
  return r;
}

/// Period from the first and last of the zero crossings of x (linear interpolation between steps).
double period(const PistonRun& r) {
  std::vector<double> zc;
  for (std::size_t i = 1; i < r.x.size(); ++i)
    if ((r.x[i - 1] > 0) != (r.x[i] > 0)) zc.push_back(r.t[i - 1] + (r.t[i] - r.t[i - 1]) * r.x[i - 1] / (r.x[i - 1] - r.x[i]));
  if (zc.size() < 3) return NAN;
  return 2 * (zc.back() - zc.front()) / double(zc.size() - 1);
}

double exactPeriod(double m) { return 2 * M_PI / std::sqrt(kStiffness / (m + kAddedMass)); }

/// Runs ~1.3 periods at 100 steps per period.
std::vector<std::string> sized(double m, std::vector<std::string> more = {}) {
  const double T = exactPeriod(m);
  more.push_back("bodies.members.piston.mass=" + std::to_string(m));
  more.push_back("time.dt=" + std::to_string(T / 100));
  more.push_back("time.endTime=" + std::to_string(1.3 * T));
  return more;
}

std::string inputError(const std::vector<std::string>& sets) { return mfsi::test::sceneInputError(kScene, sets); }

}  // namespace

TEST(PistonScene, ImplicitCouplingMeetsTheAddedMassFrequencyFromTenToOneHundredth) {
  for (const double ratio : {10.0, 1.0, 0.1, 0.01}) {  // m / m_a
    const double m = ratio * kAddedMass;
    const PistonRun r = run(sized(m), "implicit_" + std::to_string(ratio));
    ASSERT_EQ(r.status, "ok") << r.error;
    const double T = period(r), T0 = exactPeriod(m);
    EXPECT_NEAR(T / T0, 1.0, 0.01) << "m / m_a = " << ratio << ": period " << T << ", exact " << T0;
    // The dry period lies at least four tolerances away even at m / m_a = 10 (4.7 %): the test sees the fluid.
    const double dry = 2 * M_PI / std::sqrt(kStiffness / m);
    EXPECT_GT(std::abs(T - dry), 0.04 * T0) << "m / m_a = " << ratio;
    // Every step converged; IQN-ILS solves each step's linear fixed point with one secant (2 fluid
    // solves) and confirms it with a third.
    EXPECT_EQ(r.result.metrics.at("coupling.unconverged_steps"), 0.0);
    EXPECT_LE(r.result.metrics.at("coupling.mean_iterations"), 3.0) << "m / m_a = " << ratio;
  }
}

TEST(PistonScene, ExplicitCouplingDivergesUnderStrongAddedMassAndNotUnderWeak) {
  // m_a / m = 100: the staggered scheme's error grows ~100-fold per step.
  const PistonRun strong = run(sized(0.01 * kAddedMass, {"coupling.scheme=explicit"}), "explicit_strong");
  EXPECT_EQ(strong.status, "diverged");
  EXPECT_LT(strong.steps(), 10);
  // m_a / m = 0.1: it runs and keeps the period (within 1 %).
  const double m = 10 * kAddedMass;
  const PistonRun weak = run(sized(m, {"coupling.scheme=explicit"}), "explicit_weak");
  ASSERT_EQ(weak.status, "ok") << weak.error;
  EXPECT_NEAR(period(weak) / exactPeriod(m), 1.0, 0.01);
  EXPECT_EQ(weak.result.metrics.at("coupling.mean_iterations"), 1.0);
}

TEST(PistonScene, AitkenMeetsTheSameAnswerWhenOmegaMayReachTheSecant) {
  // The step's map has slope -m_a/m = -100: Aitken's secant omega is 1/101, below the default
  // omegaMin = 0.05, so the scene's Aitken run needs omegaMin lowered.
  const double m = 0.01 * kAddedMass;
  const PistonRun a =
      run(sized(m, {"coupling.iqnMaxCols=0", "coupling.omegaMin=0.001", "coupling.omegaInit=0.005"}), "aitken");
  ASSERT_EQ(a.status, "ok") << a.error;
  const PistonRun q = run(sized(m), "iqn");
  ASSERT_EQ(q.status, "ok") << q.error;
  ASSERT_EQ(a.x.size(), q.x.size());
  double diff = 0;
  for (std::size_t i = 0; i < a.x.size(); ++i) diff = std::max(diff, std::abs(a.x[i] - q.x[i]));
  EXPECT_LT(diff, 1e-6 * 1e-3) << "piston positions (amplitude 1e-3 m) differ by " << diff;
  EXPECT_EQ(a.result.metrics.at("coupling.unconverged_steps"), 0.0);
}

TEST(PistonScene, AitkenBoundedAboveTheSecantIsStoppedAsDivergedByTheCoupling) {
  // Default omegaMin = 0.05 > 1/101: each iteration multiplies the error by 1 - 0.05 * 101 = -4;
  // the coupling stops the step itself, naming the cause, before the fluid breaks.
  const PistonRun a = run(sized(0.01 * kAddedMass, {"coupling.iqnMaxCols=0"}), "aitken_bounded");
  EXPECT_EQ(a.status, "diverged");
  EXPECT_NE(a.error.find("coupling: the interface residual grew"), std::string::npos) << a.error;
  EXPECT_NE(a.error.find("omegaMin"), std::string::npos) << a.error;
  EXPECT_LT(a.steps(), 2);
}

TEST(PistonScene, MaxMeshVelocityLimitsEachIterationNotTheAnswer) {
  // The piston moves at up to 0.0106 m/s; a limit of 0.002 m/s per iteration shortens most
  // updates, the step takes more iterations and lands on the same fixed point.
  const PistonRun free = run({"time.endTime=0.3"}, "velocity_free");
  const PistonRun slow = run({"time.endTime=0.3", "coupling.maxMeshVelocity=0.002"}, "velocity_limited");
  ASSERT_EQ(free.status, "ok") << free.error;
  ASSERT_EQ(slow.status, "ok") << slow.error;
  EXPECT_EQ(free.result.metrics.at("coupling.limited_updates"), 0.0);
  EXPECT_GT(slow.result.metrics.at("coupling.limited_updates"), 50.0);
  EXPECT_GT(slow.result.metrics.at("coupling.mean_iterations"), free.result.metrics.at("coupling.mean_iterations") + 2);
  EXPECT_EQ(slow.result.metrics.at("coupling.unconverged_steps"), 0.0);
  ASSERT_EQ(free.x.size(), slow.x.size());
  for (std::size_t i = 0; i < free.x.size(); ++i) EXPECT_NEAR(slow.x[i], free.x[i], 1e-11) << "step " << i;
}

TEST(PistonScene, BodyCouplingInputErrorsNameTheKey) {
  std::string e = inputError({"coupling.bodyPatches={pistn: [piston]}"});
  EXPECT_NE(e.find("bodyPatches.pistn"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'piston'"), std::string::npos) << e;
  e = inputError({"coupling.bodyPatches={piston: [pistn]}"});
  EXPECT_NE(e.find("bodyPatches.piston.0"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'piston'"), std::string::npos) << e;
  // The piston's fluid wall must take the mesh velocity.
  e = inputError({"fluid.boundary.piston.type=wall"});
  EXPECT_NE(e.find("movingWall"), std::string::npos) << e;
  EXPECT_NE(e.find("bodyPatches.piston.0"), std::string::npos) << e;
}
