// Checkpoints of the structure modules (MembraneModule, RigidModule: saveState / loadState, then
// openOutput with the OutputStart of a restart): N steps, a checkpoint, a new module and N more
// steps end where 2N steps in one module do, bitwise, with the same reports; bodies.csv of a run
// that continues its files equals the one of the straight run byte for byte (the rows the stopped
// run wrote after the checkpoint are dropped); every write of bodies.csv is checked.
#include "coupling/MembraneModule.hpp"
#include "coupling/RigidModule.hpp"

#include "core/Error.hpp"
#include "core/io/HostCopy.hpp"
#include "support/TextFiles.hpp"
#include "support/FreshDir.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace mfsi;

namespace {

const double kPi = std::acos(-1.0);

using mfsi::test::readFile;

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

void save(const Module& m, const std::string& path) {
  io::Hdf5File file = io::Hdf5File::create(path);
  io::StateWriter w(file, "/" + m.name());
  m.saveState(w);
  file.commit();
}

void load(Module& m, const std::string& path) {
  const io::Hdf5File file = io::Hdf5File::openRead(path);
  m.loadState(io::StateReader(file, "/" + m.name()));
}

/// Steps of a run driver: the time accumulates as Simulation's does.
struct Clock {
  TimeState ts;
  explicit Clock(double dt) { ts.dt = ts.dtOld = dt; }
  void advance(Module& m, int steps) {
    for (int k = 0; k < steps; ++k) {
      m.advance(ts);
      ts.time += ts.dt;
      ++ts.step;
    }
  }
};

std::map<std::string, double> metrics(const Module& m) {
  std::map<std::string, double> out;
  m.addMetrics(out);
  return out;
}

std::vector<double> stepValues(const Module& m) {
  std::vector<double> v;
  m.appendStepValues(v);
  return v;
}

/// A clamped pre-stressed square: static under a pressure ramp, or vibrating from its (1,1) mode.
MembranePanelOptions square(MembraneAnalysis analysis) {
  MembranePanelOptions p;
  p.name = "membrane";
  p.mesh.rectangle.nx = p.mesh.rectangle.ny = 6;
  p.options.material = {1e7, 0.3, 1e-3, 1000, 100};
  p.options.tolerance = 1e-9;
  p.analysis = analysis;
  if (analysis == MembraneAnalysis::Static) {
    p.loads.pressure = 5;
    p.pressureTime.shape = MembraneTimeShape::Ramp;
    p.pressureTime.rampTime = 1;
    const MembraneTimeFunction f = p.pressureTime;
    p.loads.pressureTime = [f](real t) { return f(t); };
  } else {
    p.initial.shape = MembraneInitialShape::SineMode;
    p.initial.amplitude = 1e-4;
    p.reference = MembraneReference::SquareFrequency;
  }
  return p;
}

/// 2N steps against N, a checkpoint, a new module (opened as a restart in the same folder) and N more.
void expectMembraneRestart(MembraneAnalysis analysis, double dt, int half, const std::string& tag) {
  const std::string dir = test::freshDir(tag), path = dir + "/state.h5";
  MembraneModule straight(square(analysis));
  straight.openOutput(dir, {});
  Clock c0(dt);
  c0.advance(straight, 2 * half);

  MembraneModule first(square(analysis));
  first.openOutput(dir, {});
  Clock c1(dt);
  c1.advance(first, half);
  save(first, path);
  MembraneModule resumed(square(analysis));
  load(resumed, path);
  resumed.openOutput(dir, {half, true});  // a static panel must not solve t = 0 again
  c1.advance(resumed, half);

  const std::size_t n = 3 * static_cast<std::size_t>(straight.solver().mesh().nNodes());
  EXPECT_EQ(io::hostValues(resumed.solver().displacement(), n), io::hostValues(straight.solver().displacement(), n));
  EXPECT_EQ(io::hostValues(resumed.solver().velocity(), n), io::hostValues(straight.solver().velocity(), n));
  EXPECT_EQ(stepValues(resumed), stepValues(straight));
  EXPECT_EQ(metrics(resumed), metrics(straight));
}

RigidSystemOptions oscillator() {
  // The spring-mass-damper of test_rigid.cpp under gravity, with a second, free-falling body.
  RigidSystemOptions opt;
  RigidBodyOptions m;
  m.name = "mass";
  m.mass = 2;
  m.joint.type = RigidJointType::Py;
  m.joint.q0 = {0.1};
  RigidBodyOptions f = m;
  f.name = "faller";
  f.joint.q0 = {0.0};
  opt.bodies = {m, f};
  RigidLinearSpringOptions s;
  s.name = "spring";
  s.body = "mass";
  s.anchor = {0, 10, 0};
  s.restLength = 10;
  s.stiffness = 8 * kPi * kPi;  // 1 s period
  s.damping = 0.4 * kPi;        // 5 % of critical
  opt.linearSprings.push_back(s);
  opt.gravity = {0, -9.81, 0};
  return opt;
}

}  // namespace

TEST(StructureModuleCheckpoint, StaticMembraneRestartIsBitwise) {
  expectMembraneRestart(MembraneAnalysis::Static, 0.1, 4, "module_checkpoint_static");
}

TEST(StructureModuleCheckpoint, DynamicMembraneRestartKeepsItsPeriodRecord) {
  // Two and a half periods of the (1,1) mode at 40 steps per period: the period metric comes from
  // the centre-deflection record of both halves.
  const double T = 1 / rectangleMembraneFrequency(100, 1, 1, 1, 1, 1);
  expectMembraneRestart(MembraneAnalysis::Dynamic, T / 40, 50, "module_checkpoint_dynamic");
}

TEST(StructureModuleCheckpoint, BodiesCsvContinuesOrStartsAfresh) {
  const double dt = 0.01;
  const int half = 20;
  const std::string straightDir = test::freshDir("module_checkpoint_bodies_straight");
  const std::string runDir = test::freshDir("module_checkpoint_bodies_run");
  const std::string newDir = test::freshDir("module_checkpoint_bodies_new");
  const std::string path = runDir + "/state.h5";
  {
    RigidModule straight(oscillator());
    straight.openOutput(straightDir, {});
    Clock c(dt);
    c.advance(straight, 2 * half);
  }
  Clock c(dt);
  {
    // The run to continue went on 3 steps past its checkpoint before it stopped.
    RigidModule first(oscillator());
    first.openOutput(runDir, {});
    c.advance(first, half);
    save(first, path);
    Clock later = c;
    later.advance(first, 3);
  }
  const std::vector<std::string> straight = lines(readFile(straightDir + "/bodies.csv"));
  ASSERT_EQ(straight.size(), 1u + 2u * (2 * half + 1));  // header, then 2 bodies at set-up and per step
  {
    RigidModule resumed(oscillator());
    load(resumed, path);
    resumed.openOutput(runDir, {half, true});
    Clock rc = c;
    rc.advance(resumed, half);
    RigidModule straightAgain(oscillator());
    Clock sc(dt);
    sc.advance(straightAgain, 2 * half);
    EXPECT_EQ(metrics(resumed), metrics(straightAgain));
  }
  EXPECT_EQ(readFile(runDir + "/bodies.csv"), readFile(straightDir + "/bodies.csv"));
  // Restarted into a new folder: the header, then the checkpoint's state and the steps after it;
  // then that run too is stopped (after a checkpoint 5 steps in) and continued in its folder.
  const std::string path2 = newDir + "/state.h5";
  const int more = 5;
  Clock c2 = c;
  {
    RigidModule resumed(oscillator());
    load(resumed, path);
    resumed.openOutput(newDir, {half, false, 0});
    c2.advance(resumed, more);
    save(resumed, path2);
    Clock later = c2;
    later.advance(resumed, 2);
  }
  {
    RigidModule resumed(oscillator());
    load(resumed, path2);
    resumed.openOutput(newDir, {half + more, true, half});
    c2.advance(resumed, half - more);
  }
  std::vector<std::string> expected = {straight.front()};
  expected.insert(expected.end(), straight.begin() + 1 + 2 * half, straight.end());
  EXPECT_EQ(lines(readFile(newDir + "/bodies.csv")), expected);
}

TEST(StructureModuleCheckpoint, BodiesCsvErrors) {
  // Continuing a file that is not there names it.
  const std::string empty = test::freshDir("module_checkpoint_bodies_missing");
  RigidModule missing(oscillator());
  try {
    missing.openOutput(empty, {5, true});
    ADD_FAILURE() << "continued a bodies.csv that does not exist";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bodies.csv"), std::string::npos) << e.what();
  }
  // A folder it cannot be created in names it. (A disk that fills while it is written:
  // FullDisk.ABodiesCsvThatCannotBeWrittenKeepsWholeRows, which checks the rows kept whole.)
  const std::string nowhere = test::freshDir("module_checkpoint_bodies_nowhere") + "/no/such/folder";
  RigidModule module(oscillator());
  try {
    module.openOutput(nowhere, {});
    ADD_FAILURE() << "bodies.csv in a folder that does not exist";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(nowhere + "/bodies.csv"), std::string::npos) << e.what();
  }
}
