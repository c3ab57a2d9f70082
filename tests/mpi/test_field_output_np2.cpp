// Field output of a decomposed grid on 2 ranks: each rank writes its own rows of one shared HDF5
// file (no gather). The frames and the index are those a one-rank series writes of the whole grid,
// dataset by dataset bitwise; a frame whose points did not move refers to the earlier file as on
// one rank; a disk that fills on either rank fails the frame on both, with one message and no file,
// and so does a fault (a malformed grid) on one rank alone, instead of leaving the other waiting.
#include "core/Error.hpp"
#include "core/io/FieldOutput.hpp"
#include "core/io/Hdf5File.hpp"

#include <gtest/gtest.h>
#include <mpi.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace mfsi::io;

namespace {

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

/// The same empty folder on both ranks.
std::string sharedDir(const std::string& tag) {
  const std::string dir = ::testing::TempDir() + "/field_output_np2_" + tag;
  if (rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr std::int64_t kPoints = 5000, kCells = 3000;

/// Who owns a global row: runs of varying length, alternating between the ranks (a partition's
/// rows are never one block).
int owner(std::int64_t id) { return static_cast<int>((id / (1 + id % 7) + id / 13) % 2); }

/// The hex grid of frame `step` whole (`part` < 0) or rank `part`'s rows of it, with a surface grid
/// that only rank 0's frame holds whole (another rank's copy differs, and must not be written).
FieldFrame frame(long long step, double move, int part) {
  FieldFrame f;
  f.time = 0.5 * static_cast<double>(step);
  f.step = step;
  OutputGrid g;
  g.name = "mesh";
  g.shape = CellShape::Hexahedron;
  g.decomposed = part >= 0;
  g.globalPoints = kPoints;
  g.globalCells = kCells;
  std::vector<double> d, u, p, q;
  for (std::int64_t i = 0; i < kPoints; ++i) {
    if (part >= 0 && owner(i) != part) continue;
    g.pointRows.push_back(i);
    for (int k = 0; k < 3; ++k) g.points.push_back(0.001 * static_cast<double>(i) + k + move);
    for (int k = 0; k < 3; ++k) d.push_back(move * (k + 1) + 1e-7 * static_cast<double>(i));
  }
  for (std::int64_t c = 0; c < kCells; ++c) {
    if (part >= 0 && owner(c + 11) != part) continue;
    g.cellRows.push_back(c);
    for (int a = 0; a < 8; ++a) g.cells.push_back((c * 8 + a * 97) % kPoints);
    for (int k = 0; k < 3; ++k) u.push_back(std::sin(0.01 * static_cast<double>(c) + k) * static_cast<double>(step + 1));
    p.push_back(1.0 / static_cast<double>(c + 1) + static_cast<double>(step));
    q.push_back(0.5 + 1e-4 * static_cast<double>(c % 17));
  }
  if (part < 0) {
    g.pointRows.clear();
    g.cellRows.clear();
  }
  g.addPointField("meshDisplacement", 3, d, true, true);
  g.addCellField("scaledJacobian", 1, q, true, true);
  g.addCellField("U", 3, u);
  g.addCellField("p", 1, p);
  OutputGrid s;
  s.name = "membrane";
  s.shape = CellShape::Surface;
  const double z = part > 0 ? -99.0 : 1.0;  // what another rank holds is not written
  s.points = {0, 0, z, 1, 0, z, 1, 1, z, 0, 1, z, 2, 0, z};
  s.cells = {0, 1, 2, 3, 1, 4, 2, -1};
  s.addPointField("displacement", 3, std::vector<double>(15, 0.25 * static_cast<double>(step)));
  f.grids.push_back(std::move(g));
  f.grids.push_back(std::move(s));
  return f;
}

void expectSameFile(const std::string& a, const std::string& b) {
  const Hdf5File x = Hdf5File::openRead(a), y = Hdf5File::openRead(b);
  ASSERT_EQ(x.datasets(), y.datasets()) << a << " / " << b;
  EXPECT_EQ(x.readAttribute("time"), y.readAttribute("time"));
  for (const std::string& name : x.datasets()) {
    ASSERT_EQ(x.holdsIntegers(name), y.holdsIntegers(name)) << name;
    ASSERT_EQ(x.shape(name), y.shape(name)) << name;
    if (x.holdsIntegers(name))
      EXPECT_EQ(x.readInts(name), y.readInts(name)) << name;
    else
      EXPECT_EQ(x.readDoubles(name), y.readDoubles(name)) << name;  // bitwise
  }
}

/// Step 1, step 2 with the points moved, step 3 with the points where step 2 had them.
const std::vector<std::pair<long long, double>> kSteps = {{1, 0.0}, {2, 0.125}, {3, 0.125}};

}  // namespace

TEST(FieldOutputNp2, EachRankWritesItsRowsOfTheOneRankFile) {
  const std::string dir = sharedDir("frames");
  if (rank() == 0) {
    FieldSeries whole(dir + "/one");
    for (const auto& [step, move] : kSteps) whole.write(frame(step, move, -1));
  }
  FieldSeries shared(dir + "/two", MPI_COMM_WORLD);
  for (const auto& [step, move] : kSteps) shared.write(frame(step, move, rank()));
  EXPECT_EQ(shared.frames(), 3);
  if (rank() != 0) return;
  // The index is the one-rank index (file names are relative to the run folder): the third frame
  // refers to the second's points and geometric fields, as on one rank.
  const std::string index = read(dir + "/two/fields.xdmf");
  EXPECT_EQ(index, read(dir + "/one/fields.xdmf"));
  EXPECT_NE(index.find("fields/fields_000002.h5:/mesh/points"), std::string::npos);
  EXPECT_EQ(index.find("fields/fields_000003.h5:/mesh/points"), std::string::npos);
  for (const auto& [step, move] : kSteps) {
    char name[64];
    std::snprintf(name, sizeof name, "/fields/fields_%06lld.h5", step);
    expectSameFile(dir + "/one" + name, dir + "/two" + name);
  }
  for (const auto& e : fs::directory_iterator(dir + "/two/fields"))
    EXPECT_NE(e.path().extension(), ".part") << e.path();
}

namespace {
/// Each rank's file size limit (bytes, 0: none) while a frame is written: a write beyond it fails
/// as one to a full disk does (EFBIG, the signal ignored).
void writeUnderLimit(FieldSeries& series, const FieldFrame& f, rlim_t limit, std::string& error) {
  struct rlimit old {};
  getrlimit(RLIMIT_FSIZE, &old);
  auto previous = std::signal(SIGXFSZ, SIG_IGN);
  if (limit > 0) {
    struct rlimit lim = old;
    lim.rlim_cur = limit;
    setrlimit(RLIMIT_FSIZE, &lim);
  }
  try {
    series.write(f);
  } catch (const mfsi::OutputError& e) {
    error = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, previous);
}
}  // namespace

TEST(FieldOutputNp2, AFullDiskOnEitherRankFailsTheFrameOnBoth) {
  const std::string dir = sharedDir("full");
  FieldSeries series(dir, MPI_COMM_WORLD);
  series.write(frame(1, 0.0, rank()));
  const std::string before = rank() == 0 ? read(dir + "/fields.xdmf") : "";
  // A limit of 200 KiB on both ranks: the layout (its metadata block of 64 KiB and the surface)
  // fits, the mesh's 0.36 MB of moved rows do not. Then 16 KiB
  // on rank 0 alone: it cannot even lay the file out.
  for (int full : {-1, 0}) {
    std::string error;
    const rlim_t limit = full < 0 ? 200 << 10 : (rank() == full ? 16 << 10 : 0);
    writeUnderLimit(series, frame(2, 0.5, rank()), limit, error);
    EXPECT_NE(error.find("fields_000002.h5"), std::string::npos) << "rank " << rank() << ": " << error;
    EXPECT_NE(error.find("is the disk full?"), std::string::npos) << "rank " << rank() << ": " << error;
    EXPECT_EQ(error.find(".part"), std::string::npos) << "names the file it is published as: " << error;
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank() == 0) {
      EXPECT_FALSE(fs::exists(dir + "/fields/fields_000002.h5")) << "limit case " << full;
      EXPECT_FALSE(fs::exists(dir + "/fields/fields_000002.h5.part")) << "limit case " << full;
      EXPECT_EQ(read(dir + "/fields.xdmf"), before);
    }
    EXPECT_EQ(series.frames(), 1);
  }
  // And the series goes on once there is room again.
  series.write(frame(2, 0.5, rank()));
  EXPECT_EQ(series.frames(), 2);
  if (rank() == 0) {
    EXPECT_TRUE(fs::exists(dir + "/fields/fields_000002.h5"));
  }
}

TEST(FieldOutputNp2, AFaultOnOneRankAloneStopsTheFrameOnBoth) {
  const std::string dir = sharedDir("fault");
  FieldSeries series(dir, MPI_COMM_WORLD);
  series.write(frame(1, 0.0, rank()));
  // A field of the wrong size: in the surface grid that rank 0 alone writes, then in rank 1's
  // part of the mesh. Each is found by that rank alone, while rank 0 lays the file out.
  for (int faulty : {0, 1}) {
    FieldFrame f = frame(2, 0.5, rank());
    if (rank() == faulty) {
      auto& grid = f.grids[faulty == 0 ? 1 : 0];
      grid.pointFields[0].values.pop_back();
    }
    std::string error;
    try {
      series.write(f);
    } catch (const std::exception& e) {  // rank 0's layout: an OutputError; rank 1's rows: a logic_error
      error = e.what();
    }
    const std::string field = faulty == 0 ? "/membrane/point/displacement" : "meshDisplacement";
    EXPECT_NE(error.find(field), std::string::npos) << "rank " << rank() << ", fault on rank " << faulty << ": " << error;
    EXPECT_EQ(error.find(".part"), std::string::npos) << "names the file it is published as: " << error;
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank() == 0) {
      EXPECT_FALSE(fs::exists(dir + "/fields/fields_000002.h5")) << "fault on rank " << faulty;
      EXPECT_FALSE(fs::exists(dir + "/fields/fields_000002.h5.part")) << "fault on rank " << faulty;
    }
    EXPECT_EQ(series.frames(), 1);
  }
  series.write(frame(2, 0.5, rank()));
  EXPECT_EQ(series.frames(), 2);
}
