// A disk that fills during a run (issue 14): the run stops with exit code 4 and summary.json says
// status "error" with a message naming the file and asking "is the disk full?", and nothing it
// leaves looks complete without being so: no *.part file, every field frame fields.xdmf lists and
// every checkpoint is a whole HDF5 file, steps.csv holds whole rows. When even summary.json
// cannot be written, there is none (and the exit code is still 4): a run never claims success.
//
// The disk fills without a file system to fill: the run is started with RLIMIT_FSIZE (each file
// it writes may grow to the limit, a write beyond fails with EFBIG as one to a full disk fails
// with ENOSPC). The limits come from the sizes an unlimited run writes, so that exactly the file
// each test is about outgrows them: a field frame, the XDMF index, steps.csv, a checkpoint, the
// summary.
#include "core/io/Hdf5File.hpp"
#include "support/CubeCavity.hpp"
#include "support/FreshDir.hpp"
#include "support/Spawn.hpp"
#include "support/TextFiles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// 40 steps of the 4^3 cube cavity: a fraction of a second.
const std::string kScene = mfsi::test::cubeCavityScene(4, 0.8);

long long sizeOf(const std::string& file) { return static_cast<long long>(fs::file_size(file)); }

struct Outcome {
  std::string dir;  ///< the output folder
  int code = -1;
  std::string output;
  std::string summary;  ///< "" when there is none
};

std::string base(const std::string& tag) { return ::testing::TempDir() + "/full_disk_" + tag; }

Outcome runMfsi(const std::string& tag, const std::vector<std::string>& sets, long long fileSizeLimit) {
  Outcome r;
  mfsi::test::freshDir("full_disk_" + tag);
  const std::string scene = base(tag) + "/scene_in.yaml";
  std::ofstream(scene) << kScene;
  r.dir = base(tag) + "/run";
  std::vector<std::string> argv = {MFSI_EXE, "run", scene, "--out", r.dir};
  for (const auto& s : sets) {
    argv.push_back("--set");
    argv.push_back(s);
  }
  mfsi::test::SpawnOptions options;
  options.fileSizeLimit = fileSizeLimit;
  const auto done = mfsi::test::run(argv, options);
  r.code = done.code;
  r.output = done.output;
  if (fs::exists(r.dir + "/summary.json")) r.summary = mfsi::test::readFile(r.dir + "/summary.json");
  return r;
}

/// What an unlimited run of each kind writes, measured once in each test (ctest runs the tests of
/// this file side by side, each in its own process: each measures in a folder of its own).
struct Sizes {
  long long sceneYaml = 0, summary = 0, stepsCsv = 0, firstFrame = 0, index = 0, checkpoint = 0;
};

const Sizes& referenceSizes() {
  static const Sizes sizes = [] {
    Sizes s;
    const std::string tag = std::string("reference_") + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    const Outcome r = runMfsi(
        tag, {"output.fields.everySteps=1", "output.fields.initial=true", "output.checkpoint.everySteps=3"}, -1);
    EXPECT_EQ(r.code, 0) << r.output;
    s.sceneYaml = sizeOf(r.dir + "/scene.yaml");
    s.summary = sizeOf(r.dir + "/summary.json");
    s.stepsCsv = sizeOf(r.dir + "/steps.csv");
    s.firstFrame = sizeOf(r.dir + "/fields/fields_000000.h5");
    s.index = sizeOf(r.dir + "/fields.xdmf");
    s.checkpoint = -1;
    for (const auto& e : fs::directory_iterator(r.dir + "/checkpoints"))
      if (s.checkpoint < 0 || sizeOf(e.path().string()) < s.checkpoint) s.checkpoint = sizeOf(e.path().string());
    return s;
  }();
  return sizes;
}

/// Room for what every run writes before the file a test is about: scene.yaml (a few characters
/// longer with other --set values) and a summary with an error message (which names the folder).
long long roomForTheRest(const std::string& tag) {
  const Sizes& s = referenceSizes();
  return std::max(s.sceneYaml + 64, s.summary + 1024 + 2 * static_cast<long long>(base(tag).size()));
}

/// The HDF5 files and datasets fields.xdmf refers to ("fields/fields_000003.h5:/mesh/points").
std::vector<std::pair<std::string, std::string>> indexedDatasets(const std::string& xdmf) {
  std::vector<std::pair<std::string, std::string>> items;
  const std::string open = "Format=\"HDF\">", close = "</DataItem>";
  for (std::size_t p = xdmf.find(open); p != std::string::npos; p = xdmf.find(open, p + 1)) {
    const std::size_t b = p + open.size(), e = xdmf.find(close, b);
    const std::string item = xdmf.substr(b, e - b);
    const std::size_t colon = item.find(':');
    items.emplace_back(item.substr(0, colon), item.substr(colon + 1));
  }
  return items;
}

/// A CSV file's data rows, each checked whole: the file ends a row, and every row has the header's
/// number of values.
int wholeRows(const std::string& path) {
  const std::string csv = mfsi::test::readFile(path);
  EXPECT_FALSE(csv.empty()) << path;
  if (csv.empty()) return 0;
  EXPECT_EQ(csv.back(), '\n') << path << " ends in a cut-off row";
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  const auto commas = std::count(line.begin(), line.end(), ',');
  int rows = 0;
  for (; std::getline(in, line); ++rows)
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), commas) << path << " row " << rows + 1 << ": " << line;
  return rows;
}

/// Nothing in the run folder looks complete without being so.
void expectNothingCutShort(const Outcome& r) {
  for (const auto& e : fs::recursive_directory_iterator(r.dir))
    EXPECT_NE(e.path().extension(), ".part") << "a temporary file was left behind: " << e.path();
  // steps.csv: the header, then whole rows of as many values.
  if (fs::exists(r.dir + "/steps.csv")) wholeRows(r.dir + "/steps.csv");
  // Every dataset the index refers to reads back.
  if (fs::exists(r.dir + "/fields.xdmf")) {
    const auto items = indexedDatasets(mfsi::test::readFile(r.dir + "/fields.xdmf"));
    EXPECT_FALSE(items.empty());
    for (const auto& [file, dataset] : items) {
      try {
        const auto h5 = mfsi::io::Hdf5File::openRead(r.dir + "/" + file);
        std::size_t n = 1;
        for (std::size_t d : h5.shape(dataset)) n *= d;
        EXPECT_EQ(h5.readDoubles(dataset).size(), n) << file << ":" << dataset;
      } catch (const std::exception& e) {
        ADD_FAILURE() << "fields.xdmf lists " << file << ":" << dataset << ", which does not read: " << e.what();
      }
    }
  }
  // Every HDF5 file is whole (a frame the index could not list included).
  for (const char* folder : {"/fields", "/checkpoints"}) {
    if (!fs::exists(r.dir + folder)) continue;
    for (const auto& e : fs::directory_iterator(r.dir + folder)) {
      try {
        EXPECT_FALSE(mfsi::io::Hdf5File::openRead(e.path().string()).datasets().empty()) << e.path();
      } catch (const std::exception& ex) {
        ADD_FAILURE() << e.path() << " is not a whole HDF5 file: " << ex.what();
      }
    }
  }
}

/// Exit code 4, a summary with status "error" naming `file`, the same message on stderr.
void expectSavedError(const Outcome& r, const std::string& file) {
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.summary.find("\"status\": \"error\""), std::string::npos) << r.summary;
  EXPECT_NE(r.summary.find(file), std::string::npos) << "the message does not name " << file << ": " << r.summary;
  EXPECT_NE(r.summary.find("is the disk full?"), std::string::npos) << r.summary;
  EXPECT_NE(r.output.find("is the disk full?"), std::string::npos) << r.output;
}

long long dataRows(const Outcome& r) {
  const std::string csv = mfsi::test::readFile(r.dir + "/steps.csv");
  return static_cast<long long>(std::count(csv.begin(), csv.end(), '\n')) - 1;
}

}  // namespace

TEST(FullDisk, AFieldFrameThatCannotBeWrittenStopsTheRunAndLeavesNoFile) {
  // The first frame, at step 3, holds the mesh: larger than anything written before it.
  const std::vector<std::string> sets = {"output.fields.everySteps=3"};
  const long long limit = roomForTheRest("frame");
  ASSERT_LT(limit, referenceSizes().firstFrame) << "the limit would not stop the frame";
  const Outcome r = runMfsi("frame", sets, limit);
  expectSavedError(r, "fields/fields_000003.h5");
  expectNothingCutShort(r);
  EXPECT_FALSE(fs::exists(r.dir + "/fields/fields_000003.h5"));
  EXPECT_FALSE(fs::exists(r.dir + "/fields.xdmf"));
  EXPECT_EQ(dataRows(r), 3);
}

TEST(FullDisk, AFieldIndexThatCannotBeWrittenKeepsTheFramesItListedReadable) {
  // A frame each step: the index grows by a frame's entry each time until it outgrows the limit,
  // which the frames (the first, with the mesh, is the largest) and steps.csv fit in.
  const std::vector<std::string> sets = {"output.fields.everySteps=1", "output.fields.initial=true"};
  const Sizes& s = referenceSizes();
  const long long limit = std::max({roomForTheRest("index"), s.firstFrame, s.stepsCsv}) + 64;
  ASSERT_LT(limit, s.index / 2) << "the index would not outgrow the limit in mid-run";
  const Outcome r = runMfsi("index", sets, limit);
  expectSavedError(r, "fields.xdmf");
  expectNothingCutShort(r);
  ASSERT_TRUE(fs::exists(r.dir + "/fields.xdmf"));
  const auto listed = indexedDatasets(mfsi::test::readFile(r.dir + "/fields.xdmf"));
  const auto third = [](const auto& item) { return item.first == "fields/fields_000003.h5"; };
  EXPECT_NE(std::find_if(listed.begin(), listed.end(), third), listed.end())
      << "the failure came before several frames were listed";
}

TEST(FullDisk, AStepLogThatCannotBeWrittenKeepsWholeRows) {
  // No field output: steps.csv outgrows the limit, which scene.yaml and the summary fit in.
  const std::vector<std::string> sets = {"output.fields.final=false"};
  const long long limit = roomForTheRest("steps");
  ASSERT_LT(limit + 1000, referenceSizes().stepsCsv) << "steps.csv would not outgrow the limit in mid-run";
  const Outcome r = runMfsi("steps", sets, limit);
  expectSavedError(r, "steps.csv");
  expectNothingCutShort(r);
  const long long rows = dataRows(r);
  EXPECT_GT(rows, 3);
  EXPECT_LT(rows, 40);
  EXPECT_LE(sizeOf(r.dir + "/steps.csv"), limit);
}

TEST(FullDisk, ACheckpointThatCannotBeWrittenStopsTheRunAndLeavesNoFile) {
  const std::vector<std::string> sets = {"output.fields.final=false", "output.checkpoint.everySteps=3"};
  const long long limit = std::max(roomForTheRest("checkpoint"), referenceSizes().stepsCsv + 64);
  ASSERT_LT(limit, referenceSizes().checkpoint / 2) << "the limit would not stop the checkpoint";
  const Outcome r = runMfsi("checkpoint", sets, limit);
  expectSavedError(r, "checkpoints/checkpoint_000000003.h5");
  expectNothingCutShort(r);
  EXPECT_TRUE(fs::is_empty(r.dir + "/checkpoints"));
  EXPECT_EQ(dataRows(r), 3);
}

TEST(FullDisk, ASummaryThatCannotBeWrittenIsNoneAndTheRunStillFails) {
  // Too small for scene.yaml (the first result written) and for the summary of that failure
  // (the summary of a run that took no step is a few hundred bytes).
  const long long limit = 128;
  ASSERT_GT(referenceSizes().sceneYaml, limit);
  const Outcome r = runMfsi("summary", {}, limit);
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_FALSE(fs::exists(r.dir + "/summary.json")) << r.summary;
  EXPECT_FALSE(fs::exists(r.dir + "/scene.yaml"));
  EXPECT_FALSE(fs::exists(r.dir + "/steps.csv"));
  EXPECT_NE(r.output.find("scene.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("is the disk full?"), std::string::npos) << r.output;
  expectNothingCutShort(r);
}

TEST(FullDisk, ABodiesCsvThatCannotBeWrittenKeepsWholeRows) {
  // The double pendulum writes two rows of bodies.csv per step (1.26 MB over its 2,500 steps,
  // steps.csv 142 kB): a limit of three times steps.csv stops bodies.csv in mid-run.
  const std::string scene = std::string(MFSI_CASES_DIR) + "/double-pendulum.yaml";
  const std::string dir0 = base("bodies") + "_reference", dir = base("bodies") + "/run";
  mfsi::test::freshDir("full_disk_bodies");
  fs::remove_all(dir0);
  ASSERT_EQ(mfsi::test::run({MFSI_EXE, "run", scene, "--out", dir0}, {}).code, 0);
  long long other = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir0))
    if (e.is_regular_file() && e.path().filename() != "bodies.csv")
      other = std::max(other, static_cast<long long>(e.file_size()));
  const long long limit = 3 * other;
  ASSERT_LT(limit, sizeOf(dir0 + "/bodies.csv") / 2) << "bodies.csv would not outgrow the limit in mid-run";
  mfsi::test::SpawnOptions options;
  options.fileSizeLimit = limit;
  const auto done = mfsi::test::run({MFSI_EXE, "run", scene, "--out", dir}, options);
  Outcome r;
  r.dir = dir;
  r.code = done.code;
  r.output = done.output;
  if (fs::exists(dir + "/summary.json")) r.summary = mfsi::test::readFile(dir + "/summary.json");
  expectSavedError(r, "bodies.csv");
  expectNothingCutShort(r);
  // bodies.csv: the header, then whole rows (as many values each), nothing cut short.
  const int rows = wholeRows(dir + "/bodies.csv");
  EXPECT_GT(rows, 100);
  EXPECT_EQ(rows % 2, 0) << "a step's two rows are written together";
  EXPECT_LE(sizeOf(dir + "/bodies.csv"), limit);
}
