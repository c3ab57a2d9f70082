// Carrying a checkpoint to another decomposition (core/io/Redistribute): every rank's file of an
// old run, written here in one process, is reassembled by global id into the parts of a new
// decomposition. The reference values are computed on each new part from its own geometry (a
// cell's centre, a face's area vector with the part's own orientation), not from the ids the
// redistribution uses, so a wrong row, a lost sign or a face taken from the wrong side shows.
// The partitions keep the baffle's cells on one rank, as a run's always do.
#include "core/Error.hpp"
#include "core/io/Checkpoint.hpp"
#include "core/io/Hdf5File.hpp"
#include "core/io/Redistribute.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "support/LocalParts.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>

using namespace mfsi;

namespace {

/// What one rank holds: its mesh and ids.
struct Rank {
  std::unique_ptr<HexMesh> mesh;
  io::PartIds ids;
};

std::vector<Rank> decompose(const HexMesh& global, const std::vector<int>& cellRank, int ranks) {
  std::vector<Rank> out;
  for (int r = 0; r < ranks; ++r) {
    Rank k;
    k.mesh = std::make_unique<HexMesh>(buildHexMesh(localMeshPart(global, cellRank, ranks, r).input));
    k.ids = io::partIds(*k.mesh, global);
    out.push_back(std::move(k));
  }
  return out;
}

/// Per-entity values from a part's own geometry.
struct Fields {
  std::vector<double> cells;     // 2 per cell: centre x, y
  std::vector<double> nodes;     // 3 per node: the reference point
  std::vector<double> fluxes;    // 1 per face: area vector . (1, 2, 3), with the part's orientation
  std::vector<double> boundary;  // 1 per boundary face: centre x + 10 z (NaN on the processor patch)
};

Fields fields(const HexMesh& m) {
  auto pts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.referencePoints());
  auto cn = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.cellNodes());
  auto fn = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.faceNodes());
  auto fp = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), m.facePatch());
  Fields f;
  for (lid_t c = 0; c < m.nCells(); ++c) {
    double x = 0, y = 0;
    for (int k = 0; k < 8; ++k) x += pts(cn(c, k), 0) / 8, y += pts(cn(c, k), 1) / 8;
    f.cells.insert(f.cells.end(), {x, y});
  }
  for (lid_t n = 0; n < m.nNodes(); ++n) f.nodes.insert(f.nodes.end(), {pts(n, 0), pts(n, 1), pts(n, 2)});
  int processor = -1;
  for (std::size_t p = 0; p < m.patches().size(); ++p)
    if (m.patches()[p].name == kProcessorPatch) processor = static_cast<int>(p);
  for (lid_t s = 0; s < m.nFaces(); ++s) {
    std::array<std::array<double, 3>, 4> q;
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) q[k][d] = pts(fn(s, k), d);
    double d1[3], d2[3];
    for (int d = 0; d < 3; ++d) d1[d] = q[2][d] - q[0][d], d2[d] = q[3][d] - q[1][d];
    const double a[3] = {0.5 * (d1[1] * d2[2] - d1[2] * d2[1]), 0.5 * (d1[2] * d2[0] - d1[0] * d2[2]),
                         0.5 * (d1[0] * d2[1] - d1[1] * d2[0])};
    f.fluxes.push_back(a[0] + 2 * a[1] + 3 * a[2]);
    if (s >= m.nInternalFaces()) {
      double cx = 0, cz = 0;
      for (int k = 0; k < 4; ++k) cx += q[k][0] / 4, cz += q[k][2] / 4;
      f.boundary.push_back(fp(s) == processor ? std::nan("") : cx + 10 * cz);
    }
  }
  return f;
}

/// One old rank's checkpoint in memory: the tagged arrays, an untagged time, a part's own matrix
/// (left out) and a rank's own report (rank 0's kept).
io::Hdf5File oldFile(const Rank& r, int rank, double time = 0.25) {
  io::Hdf5File f = io::Hdf5File::scratch("rank" + std::to_string(rank));
  io::StateWriter w(f, "/modules/fluid");
  Fields v = fields(*r.mesh);
  for (double& x : v.boundary)
    if (std::isnan(x)) x = 0;  // what the fluid holds there
  const auto n = [](const std::vector<double>& x, std::size_t width) { return x.size() / width; };
  f.write("/modules/fluid/centres", v.cells, {n(v.cells, 2), 2});
  w.tag("centres", io::Entity::Cells);
  f.write("/modules/fluid/points0", v.nodes, {n(v.nodes, 3), 3});
  w.tag("points0", io::Entity::Nodes);
  f.write("/modules/fluid/phi", v.fluxes, {v.fluxes.size()});
  w.tag("phi", io::Entity::FaceFluxes);
  f.write("/modules/fluid/pb", v.boundary, {v.boundary.size()});
  w.tag("pb", io::Entity::BoundaryFaces);
  w.putReal("time", time);
  w.put("matrix", std::vector<double>(7, static_cast<double>(rank)));
  w.tag("matrix", io::Entity::Part);
  w.put("seconds", std::vector<double>{1.0 + rank});
  w.tag("seconds", io::Entity::RankOwn);
  return f;
}

void expectNear(const std::vector<double>& got, const std::vector<double>& want, const char* what, int rank) {
  ASSERT_EQ(got.size(), want.size()) << what << " on new rank " << rank;
  for (std::size_t i = 0; i < got.size(); ++i)
    if (!std::isnan(want[i])) {  // a processor face's boundary value is never read
      ASSERT_NEAR(got[i], want[i], 1e-14) << what << " row " << i << " on new rank " << rank;
    }
}

/// Write on `from` (a decomposition), carry to `to`, and compare every new part with its own fields.
void carry(const std::vector<Rank>& from, const std::vector<Rank>& to) {
  std::vector<io::Hdf5File> files;
  for (std::size_t r = 0; r < from.size(); ++r) files.push_back(oldFile(from[r], static_cast<int>(r)));
  std::vector<const io::Hdf5File*> parts;
  std::vector<io::PartIds> old;
  for (std::size_t r = 0; r < from.size(); ++r) parts.push_back(&files[r]), old.push_back(from[r].ids);
  for (std::size_t r = 0; r < to.size(); ++r) {
    io::Hdf5File out = io::Hdf5File::scratch("new" + std::to_string(r));
    io::redistribute(parts, old, to[r].ids, out);
    const Fields want = fields(*to[r].mesh);
    const int k = static_cast<int>(r);
    expectNear(out.readDoubles("/modules/fluid/centres"), want.cells, "cell centres", k);
    expectNear(out.readDoubles("/modules/fluid/points0"), want.nodes, "node points", k);
    expectNear(out.readDoubles("/modules/fluid/phi"), want.fluxes, "oriented face fluxes", k);
    expectNear(out.readDoubles("/modules/fluid/pb"), want.boundary, "boundary-face values", k);
    EXPECT_EQ(out.readDoubles("/modules/fluid/time"), std::vector<double>{0.25});
    EXPECT_EQ(out.readDoubles("/modules/fluid/seconds"), std::vector<double>{1.0});  // rank 0's
    EXPECT_FALSE(out.has("/modules/fluid/matrix"));  // rebuilt by the solver
  }
}

/// A random partition (nearly every face cut) with the baffle's cells on one rank.
std::vector<int> randomKeepingPanel(const HexMeshInput& in, int ranks) {
  std::vector<int> r = test::randomPartition(in.cells.size(), ranks);
  const auto panel = test::keepPanelTogether(in, ranks).keepTogether[0];
  for (lid_t c : panel) r[c] = r[panel[0]];
  return r;
}

std::vector<int> metisKeepingPanel(const HexMeshInput& in, int ranks) {
  return partitionCells(in, test::keepPanelTogether(in, ranks)).cellRank;
}

}  // namespace

TEST(Redistribute, FaceIdsOfTheWholeMeshAreTheIdentity) {
  const HexMesh global = buildHexMesh(test::longBoxWithBaffle());
  const auto ids = globalFaceIds(global, global);
  for (lid_t f = 0; f < global.nFaces(); ++f) ASSERT_EQ(ids[f], f);
}

TEST(Redistribute, FaceIdsOfAPartPointTheGlobalWayOrAreMarkedReversed) {
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const auto parts = decompose(global, test::randomPartition(in.cells.size(), 3), 3);
  const Fields g = fields(global);
  long long reversed = 0;
  for (const Rank& r : parts) {
    const Fields l = fields(*r.mesh);
    for (std::size_t f = 0; f < r.ids.faces.size(); ++f) {
      const std::int64_t code = r.ids.faces[f];
      const long long gf = code >= 0 ? code : -code - 1;
      ASSERT_NEAR(l.fluxes[f], (code >= 0 ? 1.0 : -1.0) * g.fluxes[gf], 1e-15) << "face " << f;
      reversed += code < 0;
    }
  }
  EXPECT_GT(reversed, 0);  // a random partition turns some processor faces around
}

TEST(Redistribute, ThreeRandomPartsToTwoMetisParts) {
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  carry(decompose(global, randomKeepingPanel(in, 3), 3), decompose(global, metisKeepingPanel(in, 2), 2));
}

TEST(Redistribute, TwoPartsToOneAndBack) {
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const auto two = decompose(global, metisKeepingPanel(in, 2), 2);
  std::vector<Rank> one(1);
  one[0].mesh = std::make_unique<HexMesh>(buildHexMesh(in));
  one[0].ids = io::wholeMeshIds(global);
  carry(two, one);
  carry(one, two);
}

TEST(Redistribute, AnUntaggedValueThatDiffersBetweenRanksIsRefused) {
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const auto two = decompose(global, test::metisParts(in, 2), 2);
  io::Hdf5File a = oldFile(two[0], 0, 0.25), b = oldFile(two[1], 1, 0.5);
  io::Hdf5File out = io::Hdf5File::scratch("new");
  try {
    io::redistribute({&a, &b}, {two[0].ids, two[1].ids}, io::wholeMeshIds(global), out);
    FAIL() << "a time that differs between ranks was carried";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/modules/fluid/time"), std::string::npos) << e.what();
  }
}

TEST(Redistribute, FilesOfAnotherDecompositionAreRefused) {
  // Rank files from two different runs: rows no rank wrote, or counts that are not the part's.
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const auto two = decompose(global, test::metisParts(in, 2), 2);
  const auto three = decompose(global, test::randomPartition(in.cells.size(), 3), 3);
  io::Hdf5File a = oldFile(two[0], 0), b = oldFile(three[1], 1);
  io::Hdf5File out = io::Hdf5File::scratch("new");
  EXPECT_THROW(io::redistribute({&a, &b}, {two[0].ids, two[1].ids}, io::wholeMeshIds(global), out), InputError);
}
