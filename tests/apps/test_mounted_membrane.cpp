// Membranes mounted on moving rigid bodies (coupling.parentBodyPatches): a membrane baffle spans the
// gap between two rigid bars (baffles carried by two bodies with prescribed, opposite motions
// normal to the plane), in a box of fluid at rest.
//  - the membrane's edge rows move exactly with their bars (frame and membrane never gap);
//  - in between it stays continuous (a nearly massless panel, so it follows the frames' blend):
//    neighbouring rows differ by at most 0.8 of the bars' motion
//    A and sit at the blend of the two frames (taking each node's nearest frame would tear it by
//    A or 2A mid-span);
//  - every cell stays valid; input errors of parentBodyPatches name the key.
// The full scene with a spring-mounted frame is cases/membrane-channel.yaml.
#include "support/SceneErrors.hpp"

#include "core/Error.hpp"
#include "coupling/Module.hpp"
#include "coupling/Simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr double kA = 0.02;  // amplitude of the bars' motion [m]

std::string scene() {
  std::ostringstream s;
  s.precision(17);
  s << "name: mounted\n"
       "time: {endTime: 0.25, dt: 0.05}\n"
       "mesh:\n"
       "  blocks:\n"
       "    - {min: [0, 0, 0], max: [2, 1.25, 1], cells: [16, 10, 8],\n"
       "       patches: {xmin: walls, xmax: walls, ymin: walls, ymax: walls, zmin: walls, zmax: walls}}\n"
       "  baffles:\n"
       "    - {name: left, axis: x, position: 1, min: [1, 0.25, 0.25], max: [1, 0.375, 0.75]}\n"
       "    - {name: panel, axis: x, position: 1, min: [1, 0.375, 0.25], max: [1, 0.875, 0.75]}\n"
       "    - {name: right, axis: x, position: 1, min: [1, 0.875, 0.25], max: [1, 1.0, 0.75]}\n"
       "  patchTypes: {walls: wall}\n"
       "fluid:\n"
       "  density: 0.001\n"
       "  viscosity: 0.0001\n"
       "  boundary: {left: {type: movingWall}, panel: {type: movingWall}, right: {type: movingWall}}\n"
       "membranes:\n"
       "  - name: panel\n"
       "    mesh: {baffles: {patch: panel}}\n"
       "    material: {E: 1.0e7, nu: 0.3, thickness: 0.001, density: 1}\n"
       "    analysis: dynamic\n"
       "bodies:\n"
       "  members:\n";
  for (const auto& [name, sign] : std::map<std::string, double>{{"leftBar", 1.0}, {"rightBar", -1.0}})
    s << "    " << name << ":\n"
      << "      mass: 1\n"
         "      joint: {type: prescribed, axes: [Px], motion: [{type: sine, amplitude: "
      << sign * kA << ", omega: " << 2 * M_PI << "}]}\n";
  s << "coupling:\n"
       "  fsiTol: 1.0e-6\n"
       "  bodyPatches: {leftBar: [left], rightBar: [right]}\n"
       "  parentBodyPatches: {panel: [left, right]}\n";
  return s.str();
}

}  // namespace

TEST(MountedMembrane, SpansTwoIndependentlyMovingFramesWithoutATear) {
  auto cfg = mfsi::SceneConfig::fromString(scene(), "mounted.yaml", mfsi::sceneSchema(), {});
  mfsi::Simulation sim(cfg);
  const std::string dir = ::testing::TempDir() + "/mounted_membrane";
  std::filesystem::create_directories(dir);
  const auto r = sim.run(dir, false);
  const mfsi::HexMesh& mesh = sim.mesh();
  auto x = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), mesh.points());
  auto X = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), mesh.referencePoints());
  auto fn = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), mesh.faceNodes());
  // x-displacement of the panel's nodes by row (reference y), mid-span in z.
  std::map<double, double> row;
  const auto& p = mesh.patches()[mesh.patchIndex("panel_master")];
  for (mfsi::lid_t f = p.start; f < p.start + p.size; ++f)
    for (int a = 0; a < 4; ++a) {
      const auto v = fn(f, a);
      if (std::abs(X(v, 2) - 0.5) < 1e-9) row[std::round(X(v, 1) * 1000) / 1000] = x(v, 0) - X(v, 0);
    }
  ASSERT_EQ(row.size(), 5u);
  const double a = kA * std::sin(2 * M_PI * 0.25);  // the bars at t = 0.25 s: +A and -A
  EXPECT_NEAR(row.begin()->second, a, 1e-12) << "the edge on the left bar moves with it";
  EXPECT_NEAR(row.rbegin()->second, -a, 1e-12) << "the edge on the right bar moves with it";
  double maxJump = 0;
  for (auto it = std::next(row.begin()); it != row.end(); ++it)
    maxJump = std::max(maxJump, std::abs(it->second - std::prev(it)->second));
  for (const auto& [y, d] : row) std::printf("panel row y = %.3f: x-displacement %+.6f\n", y, d);
  EXPECT_LT(maxJump, 0.81 * a) << "neighbouring rows of the membrane tear apart";
  // A light fluid and a stiff membrane: the rows sit at the blend of the two frames, weights
  // 1 / d^2 (0.9 / 0.1 one cell from a bar: 0.8 A; 0.5 / 0.5 mid-span: 0), within 5 % of A.
  auto at = [&](double y) { return row.at(y); };
  EXPECT_NEAR(at(0.5), 0.8 * a, 0.05 * a);
  EXPECT_NEAR(at(0.625), 0.0, 0.05 * a);
  EXPECT_NEAR(at(0.75), -0.8 * a, 0.05 * a);
  EXPECT_GT(r.metrics.at("coupling.min_scaled_jacobian"), 0.5);
  EXPECT_EQ(r.metrics.at("coupling.unconverged_steps"), 0.0);
}

TEST(MountedMembrane, ParentInputErrorsNameTheKey) {
  const std::string file = ::testing::TempDir() + "/mounted_errors.yaml";
  {
    std::ofstream out(file);
    out << scene();
  }
  std::string e = mfsi::test::sceneInputError(file, {"coupling.parentBodyPatches={panl: [left]}"});
  EXPECT_NE(e.find("parentBodyPatches.panl"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'panel'"), std::string::npos) << e;
  e = mfsi::test::sceneInputError(file, {"coupling.parentBodyPatches={panel: [walls]}"});
  EXPECT_NE(e.find("parentBodyPatches.panel.0"), std::string::npos) << e;
  EXPECT_NE(e.find("not a patch of a coupled body"), std::string::npos) << e;
  e = mfsi::test::sceneInputError(file, {"fluid.boundary.panel.type=membraneWall"});
  EXPECT_NE(e.find("movingWall"), std::string::npos) << e;
}

namespace {

// A frame (one bar) of mass mf on a spring k along x, carrying a pre-tensioned panel of mass mp
// (rho h = 1 kg/m^2, 0.5 x 0.5 m) across the x-direction, in a fluid far too light to matter
// (rho 1e-3: an added mass of about 1e-4 kg). The frame's joint starts displaced by 0.01 m.
std::string springFrameScene(double dt, double endTime) {
  std::ostringstream s;
  s.precision(17);
  s << "name: frame-on-a-spring\n"
       "time: {endTime: "
    << endTime << ", dt: " << dt
    << "}\n"
       "mesh:\n"
       "  blocks:\n"
       "    - {min: [0, 0, 0], max: [2, 1.25, 1], cells: [8, 10, 8],\n"
       "       patches: {xmin: walls, xmax: walls, ymin: walls, ymax: walls, zmin: walls, zmax: walls}}\n"
       "  baffles:\n"
       "    - {name: bar, axis: x, position: 1, min: [1, 0.25, 0.25], max: [1, 0.375, 0.75]}\n"
       "    - {name: panel, axis: x, position: 1, min: [1, 0.375, 0.25], max: [1, 0.875, 0.75]}\n"
       "  patchTypes: {walls: wall}\n"
       "fluid:\n"
       "  density: 0.001\n"
       "  viscosity: 1.0e-6\n"
       "  boundary: {bar: {type: movingWall}, panel: {type: movingWall}, walls: {type: slip}}\n"
       "membranes:\n"
       "  - name: panel\n"
       "    mesh: {baffles: {patch: panel}}\n"
       "    material: {E: 1.0e8, nu: 0.3, thickness: 0.001, density: 1000, preStress: 2000}\n"
       "    analysis: dynamic\n"
       "    solver: {tolerance: 1.0e-10}\n"
       "bodies:\n"
       "  members:\n"
       "    frame:\n"
       "      mass: 0.25\n"
       "      centreOfMass: [1, 0.3125, 0.5]\n"
       "      inertia: [1, 1, 1, 0, 0, 0]\n"
       "      joint: {type: Px, q0: [0.01]}\n"
       "  restraints:\n"
       "    spring: {type: linearSpring, body: frame, anchor: [0, 0.3125, 0.5], attachment: [1, 0.3125, 0.5],\n"
       "             stiffness: 10, restLength: 1}\n"
       "coupling:\n"
       "  fsiTol: 1.0e-9\n"
       "  maxFsiIter: 30\n"
       "  iqnMaxCols: 20\n"
       "  bodyPatches: {frame: [bar]}\n"
       "  parentBodyPatches: {panel: [bar]}\n"
       "  meshMotion: {slidingPatches: [walls]}\n";
  return s.str();
}

/// The frame's period from the zero crossings of its CoM x about the rest position (1 m) in a run
/// of the spring-frame scene with `overrides`.
double framePeriod(const std::string& name, double dt, double endTime, const std::vector<std::string>& overrides) {
  const std::string dir = ::testing::TempDir() + "/" + name;
  std::filesystem::create_directories(dir);
  {
    auto cfg = mfsi::SceneConfig::fromString(springFrameScene(dt, endTime), "spring.yaml", mfsi::sceneSchema(),
                                             overrides);
    mfsi::Simulation sim(cfg);
    const auto r = sim.run(dir, false);
    EXPECT_EQ(r.metrics.at("coupling.unconverged_steps"), 0.0);
  }
  std::ifstream in(dir + "/bodies.csv");
  std::string line;
  std::getline(in, line);
  std::vector<double> t, x;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string a, b, c;
    std::getline(s, a, ',');
    std::getline(s, b, ',');
    std::getline(s, c, ',');
    t.push_back(std::stod(a));
    x.push_back(std::stod(c));
  }
  std::vector<double> zc;
  for (std::size_t i = 1; i < x.size(); ++i) {
    const double a = x[i - 1] - 1, b = x[i] - 1;
    if ((a > 0) != (b > 0)) zc.push_back(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b));
  }
  EXPECT_GE(zc.size(), 2u);
  return zc.size() < 2 ? 0.0 : 2 * (zc.back() - zc.front()) / double(zc.size() - 1);
}

}  // namespace

// The membrane's mass rides on its frame: the frame on its spring oscillates with the period of
// frame and panel together, 2 pi sqrt((mf + mp) / k) (0.25 + 0.25 kg: 1.405 s), not that of the
// frame alone (0.993 s), within 1 % (every step converged; the panel is stiff, so it hardly moves
// relative to the frame). Before the membrane's mass joined the frame, the frame oscillated at its
// own period and the panel's mass moved without a force.
TEST(MountedMembrane, ItsMassRidesOnTheFrame) {
  const double mf = 0.25, mp = 0.25, k = 10;
  const double T = 2 * M_PI * std::sqrt((mf + mp) / k);
  const double measured = framePeriod("mounted_spring", T / 40, 1.3 * T, {});
  std::printf("frame period %.5f s; with the panel's mass %.5f s, without %.5f s\n", measured, T,
              2 * M_PI * std::sqrt(mf / k));
  EXPECT_NEAR(measured / T, 1.0, 0.01);
}

// A slack panel (tension 2.5 N/m, its first mode at about 3 times the frame's frequency) lags the
// frame and swings in it, and its swinging pushes the frame back (the reaction of its motion
// relative to the frame): frame and panel modes together, the frame's period is the root of
//   k - (mf + mp) lambda - lambda^2 sum_j (Gamma_j^2 / m_j) / (lambda_j - lambda) = 0,
// lambda = omega^2, over the clamped square's modes (m, n odd: Gamma_j^2 / m_j = rho h a b 64 /
// (pi^4 m^2 n^2), lambda_j = (T / rho h) pi^2 (m^2 + n^2) / a^2): 2.4 % longer than the
// rigid-mass period. Measured within 0.6 % of it (without the reaction the frame kept the
// rigid-mass period, 2.4 % short).
TEST(MountedMembrane, ASwingingPanelPushesItsFrameBack) {
  const double mf = 0.25, rhoH = 1, a = 0.5, mp = rhoH * a * a, k = 10, tension = 2.5;
  auto residual = [&](double lambda) {
    double s = 0;
    for (int m = 1; m < 200; m += 2)
      for (int n = 1; n < 200; n += 2) {
        const double g = rhoH * a * a * 64 / (std::pow(M_PI, 4) * m * m * n * n);
        const double lj = tension / rhoH * M_PI * M_PI * (m * m + n * n) / (a * a);
        s += g / (lj - lambda);
      }
    return k - (mf + mp) * lambda - lambda * lambda * s;
  };
  double lo = 0.5 * k / (mf + mp), hi = k / (mf + mp);  // f(lo) > 0 > f(hi)
  ASSERT_GT(residual(lo), 0);
  ASSERT_LT(residual(hi), 0);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (residual(mid) > 0 ? lo : hi) = mid;
  }
  const double expected = 2 * M_PI / std::sqrt(lo), rigid = 2 * M_PI * std::sqrt((mf + mp) / k);
  const double measured =
      framePeriod("mounted_swing", expected / 60, 1.3 * expected,
                  {"mesh.blocks.0.cells=[8,20,16]", "membranes.0.material.E=1.0e6",
                   "membranes.0.material.preStress=" + std::to_string(tension)});
  std::printf("frame period %.5f s; frame and panel modes %.5f s; rigid panel %.5f s\n", measured, expected, rigid);
  EXPECT_GT(expected / rigid, 1.015) << "the panel's swing must matter in this set-up";
  EXPECT_NEAR(measured / expected, 1.0, 0.006);
}
