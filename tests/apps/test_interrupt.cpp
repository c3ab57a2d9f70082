// SIGINT and SIGTERM stop `mfsi run` cleanly (issue 14): after the step in progress the run writes
// a checkpoint, steps.csv up to that step and a summary with status "interrupted", and exits with
// 128 + the signal; `mfsi run --restart` then finishes it, and the whole steps.csv equals an
// uninterrupted run's (but the wall time).
#include "support/CubeCavity.hpp"
#include "support/FreshDir.hpp"
#include "support/StepsCsv.hpp"
#include "support/Spawn.hpp"
#include "support/TextFiles.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using mfsi::test::finish;

const std::string kScene = mfsi::test::cubeCavityScene(14, 8);

pid_t start(std::vector<std::string> args, const std::string& log) {
  args.insert(args.begin(), MFSI_EXE);
  return mfsi::test::start(args, log);
}

/// The file's text, "" while it does not exist (polled while the run starts).
std::string read(const std::string& file) {
  if (!std::filesystem::exists(file)) return "";
  return mfsi::test::readFile(file);
}

long rows(const std::string& csv) {
  const std::string s = read(csv);
  long n = 0;
  for (char c : s) n += c == '\n';
  return n - 1;
}

void interruptAndContinue(int signal, const std::string& tag) {
  const std::string dir = mfsi::test::freshDir("interrupt_" + tag);
  const std::string scene = dir + "/scene_in.yaml";
  std::ofstream(scene) << kScene;
  const std::string whole = dir + "/whole", run = dir + "/run";
  ASSERT_EQ(finish(start({"run", scene, "--out", whole}, dir + "/whole.log")), 0) << read(dir + "/whole.log");

  const pid_t pid = start({"run", scene, "--out", run}, dir + "/run.log");
  ASSERT_GT(pid, 0);
  // Let it take a few steps, then stop it.
  for (int i = 0; i < 600 && rows(run + "/steps.csv") < 5; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_GE(rows(run + "/steps.csv"), 5) << read(dir + "/run.log");
  kill(pid, signal);
  ASSERT_EQ(finish(pid), 128 + signal) << read(dir + "/run.log");
  const long done = rows(run + "/steps.csv");
  ASSERT_LT(done, 400) << "the run finished before the signal: nothing was tested";
  const std::string summary = read(run + "/summary.json");
  EXPECT_NE(summary.find("\"status\": \"interrupted\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"steps\": " + std::to_string(done)), std::string::npos) << summary;
  char name[64];
  std::snprintf(name, sizeof name, "/checkpoints/checkpoint_%09ld.h5", done);
  EXPECT_TRUE(std::filesystem::exists(run + name)) << run + name;
  EXPECT_NE(read(dir + "/run.log").find("--restart"), std::string::npos);

  // Continue in place to the end: the same steps as the uninterrupted run.
  ASSERT_EQ(finish(start({"run", "--restart", run}, dir + "/restart.log")), 0) << read(dir + "/restart.log");
  EXPECT_NE(read(run + "/summary.json").find("\"status\": \"ok\""), std::string::npos);
  EXPECT_EQ(rows(run + "/steps.csv"), 400);
  EXPECT_EQ(mfsi::test::stepsWithoutWallTime(run + "/steps.csv"),
            mfsi::test::stepsWithoutWallTime(whole + "/steps.csv"));
}

}  // namespace

TEST(Interrupt, SigintStopsWithACheckpointAndTheRestartFinishesTheRun) { interruptAndContinue(SIGINT, "int"); }

TEST(Interrupt, SigtermStopsWithACheckpointAndTheRestartFinishesTheRun) { interruptAndContinue(SIGTERM, "term"); }
