// Field output: the HDF5 file (checked writes, nothing visible before commit) and the XDMF time
// series (each frame's grids, topology types, and the mixed quad/triangle encoding), read back.
#include "core/Error.hpp"
#include "core/io/FieldOutput.hpp"
#include "core/io/Hdf5File.hpp"

#include "support/FreshDir.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;
using mfsi::io::CellShape;
using mfsi::io::FieldFrame;
using mfsi::io::FieldSeries;
using mfsi::io::Hdf5File;
using mfsi::io::OutputGrid;

namespace {

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// One unit hex (8 points) and a surface of one quad and one triangle on its bottom.
FieldFrame frame(double time, long long step, double scale) {
  FieldFrame f;
  f.time = time;
  f.step = step;
  OutputGrid hex;
  hex.name = "mesh";
  hex.shape = CellShape::Hexahedron;
  hex.points = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  for (double& x : hex.points) x *= scale;
  hex.cells = {0, 1, 2, 3, 4, 5, 6, 7};
  hex.addCellField("U", 3, {1.5 * scale, -2.0, 0.25});
  hex.addCellField("p", 1, {3.0 * scale});
  hex.addPointField("meshDisplacement", 3, std::vector<double>(24, scale - 1));
  f.grids.push_back(hex);
  OutputGrid surf;
  surf.name = "membrane";
  surf.shape = CellShape::Surface;
  surf.points = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0};
  surf.cells = {0, 1, 2, 3, 1, 4, 2, -1};
  surf.addCellField("vonMises", 1, {7.0, 8.0});
  surf.addCellField("strain", 3, {1, 2, 3, 4, 5, 6}, false);
  f.grids.push_back(surf);
  return f;
}

}  // namespace

TEST(Hdf5File, RoundTripAndNothingVisibleBeforeCommit) {
  const std::string dir = mfsi::test::freshDir("field_output_roundtrip");
  const std::string path = dir + "/a.h5";
  {
    Hdf5File f = Hdf5File::create(path);
    f.write("/g/sub/x", std::vector<double>{1.25, -2.5, 3e300, 4, 5, 6}, {2, 3});
    f.write("/g/ids", std::vector<std::int64_t>{-1, 9007199254740993LL}, {2});
    f.writeAttribute("time", 0.1);
    EXPECT_FALSE(fs::exists(path)) << "the file must not appear under its name before commit";
    EXPECT_TRUE(fs::exists(path + ".part"));
    f.commit();
  }
  EXPECT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".part"));
  const Hdf5File r = Hdf5File::openRead(path);
  std::vector<std::size_t> dims;
  EXPECT_EQ(r.readDoubles("/g/sub/x", &dims), (std::vector<double>{1.25, -2.5, 3e300, 4, 5, 6}));
  EXPECT_EQ(dims, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(r.readInts("/g/ids"), (std::vector<std::int64_t>{-1, 9007199254740993LL}));
  EXPECT_EQ(r.readAttribute("time"), 0.1);
  EXPECT_TRUE(r.has("/g/sub/x"));
  EXPECT_FALSE(r.has("/g/nothing/x"));
  EXPECT_THROW(r.readDoubles("/g/nothing"), mfsi::OutputError);
}

TEST(Hdf5File, AFileNeverCommittedLeavesNothingAndBadWritesThrow) {
  const std::string dir = mfsi::test::freshDir("field_output_uncommitted");
  {
    Hdf5File f = Hdf5File::create(dir + "/b.h5");
    f.write("/x", std::vector<double>{1, 2}, {2});
    EXPECT_THROW(f.write("/y", std::vector<double>{1, 2, 3}, {2}), mfsi::OutputError);  // shape mismatch
    EXPECT_THROW(f.write("/x", std::vector<double>{1, 2}, {2}), mfsi::OutputError);     // exists already
  }  // destroyed without commit (as when a run stops)
  EXPECT_FALSE(fs::exists(dir + "/b.h5"));
  EXPECT_FALSE(fs::exists(dir + "/b.h5.part"));
  EXPECT_THROW(Hdf5File::create(dir + "/no/such/folder/c.h5"), mfsi::OutputError);
  EXPECT_THROW(Hdf5File::openRead(dir + "/missing.h5"), mfsi::OutputError);
}

TEST(FieldSeries, FramesReadBackAndTheIndexListsEachGridOverTime) {
  const std::string dir = mfsi::test::freshDir("field_output_series");
  FieldSeries series(dir);
  series.write(frame(0.0, 0, 1.0));
  series.write(frame(0.5, 5, 2.0));
  ASSERT_EQ(series.frames(), 2);
  EXPECT_EQ(series.framePath(1), dir + "/fields/fields_000005.h5");

  const Hdf5File h5 = Hdf5File::openRead(series.framePath(1));
  EXPECT_EQ(h5.readAttribute("time"), 0.5);
  std::vector<std::size_t> dims;
  EXPECT_EQ(h5.readDoubles("/mesh/cell/U", &dims), (std::vector<double>{3.0, -2.0, 0.25}));
  EXPECT_EQ(dims, (std::vector<std::size_t>{1, 3}));
  EXPECT_EQ(h5.readDoubles("/mesh/cell/p", &dims), (std::vector<double>{6.0}));
  EXPECT_EQ(dims, (std::vector<std::size_t>{1}));  // a scalar field is one-dimensional
  EXPECT_EQ(h5.readDoubles("/mesh/points")[3 * 6 + 0], 2.0);  // the mesh moved: its points are written
  // Unchanged cells and the membrane's unmoved points are not written again: the first frame has them.
  EXPECT_FALSE(h5.has("/mesh/topology"));
  EXPECT_FALSE(h5.has("/membrane/points"));
  const Hdf5File first = Hdf5File::openRead(series.framePath(0));
  EXPECT_EQ(first.readInts("/mesh/topology", &dims), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(dims, (std::vector<std::size_t>{1, 8}));
  // XDMF's mixed list: type 5 (quadrilateral) and its 4 nodes, type 4 (triangle) and its 3 nodes.
  EXPECT_EQ(first.readInts("/membrane/topology"), (std::vector<std::int64_t>{5, 0, 1, 2, 3, 4, 1, 4, 2}));

  const std::string x = read(series.indexPath());
  EXPECT_EQ(count(x, "CollectionType=\"Temporal\""), 2);  // one series per grid
  EXPECT_EQ(count(x, "<Time Value=\"0.5\"/>"), 2);
  EXPECT_EQ(count(x, "<Time Value=\"0\"/>"), 2);
  EXPECT_EQ(count(x, "TopologyType=\"Hexahedron\" NumberOfElements=\"1\""), 2);
  EXPECT_EQ(count(x, "TopologyType=\"Mixed\" NumberOfElements=\"2\""), 2);
  EXPECT_EQ(count(x, "Dimensions=\"9\" NumberType=\"Int\""), 2);
  EXPECT_NE(x.find("fields/fields_000005.h5:/mesh/cell/U</DataItem>"), std::string::npos);
  EXPECT_NE(x.find("fields/fields_000005.h5:/mesh/points</DataItem>"), std::string::npos);
  EXPECT_EQ(count(x, "fields/fields_000000.h5:/mesh/topology</DataItem>"), 2);
  EXPECT_EQ(count(x, "fields/fields_000000.h5:/membrane/points</DataItem>"), 2);
  EXPECT_EQ(count(x, "fields/fields_000005.h5:/membrane/points"), 0);
  EXPECT_NE(x.find("Name=\"U\" AttributeType=\"Vector\" Center=\"Cell\""), std::string::npos);
  EXPECT_NE(x.find("Name=\"strain\" AttributeType=\"Matrix\" Center=\"Cell\""), std::string::npos);
  EXPECT_NE(x.find("Name=\"meshDisplacement\" AttributeType=\"Vector\" Center=\"Node\""), std::string::npos);
  EXPECT_FALSE(fs::exists(series.indexPath() + ".part"));
}

TEST(FieldSeries, AllQuadsOrAllTrianglesKeepTheirOwnTopologyAndBadFieldsAreRefused) {
  OutputGrid g;
  g.name = "tri";
  g.shape = CellShape::Surface;
  g.points = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.cells = {0, 1, 2, -1};
  EXPECT_THROW(g.addCellField("p", 1, {1.0, 2.0}), std::logic_error);
  EXPECT_THROW(g.addPointField("u", 3, {1.0, 2.0}), std::logic_error);
  const std::string dir = mfsi::test::freshDir("field_output_triangles");
  FieldSeries series(dir);
  FieldFrame f;
  f.grids.push_back(g);
  series.write(f);
  EXPECT_EQ(Hdf5File::openRead(series.framePath(0)).readInts("/tri/topology"), (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_NE(read(series.indexPath()).find("TopologyType=\"Triangle\" NumberOfElements=\"1\""), std::string::npos);
}

TEST(FieldSeries, AFolderThatCannotBeWrittenStopsWithAnOutputError) {
  const std::string dir = mfsi::test::freshDir("field_output_blocked");
  std::ofstream(dir + "/fields") << "a file where the frames' folder should be";
  FieldSeries series(dir);
  EXPECT_THROW(series.write(frame(0.0, 0, 1.0)), mfsi::OutputError);
  EXPECT_EQ(series.frames(), 0);
  EXPECT_FALSE(fs::exists(series.indexPath()));
}

TEST(FieldSeries, WhatDependsOnAnUnmovedMeshIsWrittenOnceAndWrittenAgainWhenItMoves) {
  const std::string dir = mfsi::test::freshDir("field_output_geometric");
  FieldSeries series(dir);
  auto grid = [](double x1, double p) {
    FieldFrame f;
    OutputGrid g;
    g.name = "g";
    g.shape = CellShape::Surface;
    g.points = {0, 0, 0, x1, 0, 0, x1, 1, 0, 0, 1, 0};
    g.cells = {0, 1, 2, 3};
    g.addCellField("p", 1, {p});
    g.addCellField("quality", 1, {x1}, true, true);
    f.grids.push_back(g);
    return f;
  };
  FieldFrame a = grid(1.0, 1.0), b = grid(1.0, 2.0), c = grid(1.5, 3.0);
  b.step = 1;
  c.step = 2;
  series.write(a);
  series.write(b);
  series.write(c);
  const Hdf5File f1 = Hdf5File::openRead(series.framePath(1));
  EXPECT_EQ(f1.readDoubles("/g/cell/p"), (std::vector<double>{2.0}));
  EXPECT_FALSE(f1.has("/g/cell/quality"));
  EXPECT_FALSE(f1.has("/g/points"));
  const Hdf5File f2 = Hdf5File::openRead(series.framePath(2));
  EXPECT_EQ(f2.readDoubles("/g/cell/quality"), (std::vector<double>{1.5}));  // the grid moved
  EXPECT_EQ(f2.readDoubles("/g/points")[3], 1.5);
  EXPECT_FALSE(f2.has("/g/topology"));
  const std::string x = read(series.indexPath());
  EXPECT_EQ(count(x, "fields/fields_000000.h5:/g/cell/quality<"), 2);
  EXPECT_EQ(count(x, "fields/fields_000002.h5:/g/cell/quality<"), 1);
  EXPECT_EQ(count(x, "fields/fields_000000.h5:/g/topology<"), 3);
  EXPECT_EQ(count(x, "fields/fields_000001.h5:/g/cell/p<"), 1);
}
