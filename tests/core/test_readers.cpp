// Gmsh and OpenFOAM polyMesh readers: the fixture meshes of tests/data/meshes (see its README.md:
// written by scripts/make_mesh_fixtures.py with scrambled numbering, or by Gmsh and OpenFOAM
// themselves) must rebuild exactly the mesh the block generator makes of the same box, and every
// bad fixture must fail with a message that names the file, the line where one applies, and the
// defect.
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/GmshReader.hpp"
#include "core/MeshGeometry.hpp"
#include "core/PolyMeshReader.hpp"
#include "support/Approx.hpp"
#include "support/FreshDir.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
#include <vector>

using mfsi::test::near;
using mfsi::test::Tol;

namespace {

const std::array<std::string, 6> kNames{"left", "right", "bottom", "top", "back", "front"};

std::string meshPath(const std::string& name) { return std::string(MFSI_TEST_DATA_DIR) + "/meshes/" + name; }

/// The box of the fixtures as the block generator makes it, with the fixture's patch names.
mfsi::HexMesh referenceBox(std::array<double, 3> lo, std::array<double, 3> hi, std::array<int, 3> n,
                           std::array<double, 3> grading, const std::array<std::string, 6>& names,
                           const std::function<std::array<double, 3>(std::array<double, 3>)>& transform = {}) {
  auto spec = mfsi::boxSpec(lo, hi, n);
  spec.blocks[0].grading = grading;
  spec.blocks[0].patches = names;
  auto in = mfsi::generateBlockMesh(spec);
  if (transform)
    for (auto& p : in.points) p = transform(p);
  return mfsi::buildHexMesh(in);
}

using Points = std::vector<std::array<double, 3>>;

/// Sort points lexicographically on coordinates rounded to 1e-9, so round-off cannot reorder them.
void sortPoints(Points& p) {
  auto key = [](const std::array<double, 3>& a) {
    return std::array<long long, 3>{std::llround(a[0] * 1e9), std::llround(a[1] * 1e9), std::llround(a[2] * 1e9)};
  };
  std::sort(p.begin(), p.end(), [&](const auto& a, const auto& b) { return key(a) < key(b); });
}

template <class View>
Points rows(const View& v, int begin, int end) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  Points out;
  for (int i = begin; i < end; ++i) out.push_back({h(i, 0), h(i, 1), h(i, 2)});
  sortPoints(out);
  return out;
}

::testing::AssertionResult samePoints(const Points& a, const Points& b, const std::string& what, double tol) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << what << ": " << a.size() << " vs " << b.size() << " points";
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      auto r = near(a[i][k], b[i][k], Tol{tol, 0});
      if (!r) return ::testing::AssertionFailure() << what << "[" << i << "][" << k << "] " << r.message();
    }
  return ::testing::AssertionSuccess();
}

/// `mesh` must equal `ref` up to numbering: counts, patches (ref patch `refNames[i]` is called
/// `names[i]` in `mesh`), volume, cell centroids, nodes and the face centroids of every patch, to
/// `tol` in coordinates (and relative to it in volumes).
void expectSameMesh(const mfsi::HexMesh& mesh, const mfsi::HexMesh& ref, const std::array<std::string, 6>& names,
                    const std::array<std::string, 6>& refNames, double tol = 1e-12) {
  EXPECT_EQ(mesh.nCells(), ref.nCells());
  EXPECT_EQ(mesh.nNodes(), ref.nNodes());
  EXPECT_EQ(mesh.nFaces(), ref.nFaces());
  EXPECT_EQ(mesh.nInternalFaces(), ref.nInternalFaces());
  ASSERT_EQ(mesh.patches().size(), ref.patches().size()) << "no default patch: every boundary face is in a named patch";

  auto g = mfsi::allocateGeometry(mesh);
  auto gr = mfsi::allocateGeometry(ref);
  mfsi::computeGeometry(mfsi::ExecSpace(), mesh, g);
  mfsi::computeGeometry(mfsi::ExecSpace(), ref, gr);
  const auto q = mfsi::computeQuality(mfsi::ExecSpace(), mesh, g);
  const auto qr = mfsi::computeQuality(mfsi::ExecSpace(), ref, gr);
  EXPECT_TRUE(near(q.totalVolume, qr.totalVolume, Tol{0, 1e-13}, "total volume"));
  EXPECT_TRUE(near(q.minVolume, qr.minVolume, Tol{0, tol}, "min cell volume"));
  EXPECT_TRUE(near(q.minScaledJacobian, qr.minScaledJacobian, Tol{tol, 0}, "min scaled Jacobian"));
  EXPECT_TRUE(near(q.maxNonOrthogonality, qr.maxNonOrthogonality, Tol{1e-9, 0}, "max non-orthogonality"));
  EXPECT_TRUE(samePoints(rows(g.cellCentroid, 0, mesh.nCells()), rows(gr.cellCentroid, 0, ref.nCells()),
                         "cell centroids", tol));
  EXPECT_TRUE(samePoints(rows(mesh.points(), 0, mesh.nNodes()), rows(ref.points(), 0, ref.nNodes()), "nodes", tol));
  for (int s = 0; s < 6; ++s) {
    const auto& p = mesh.patches()[mesh.patchIndex(names[s])];
    const auto& pr = ref.patches()[ref.patchIndex(refNames[s])];
    EXPECT_EQ(p.size, pr.size) << names[s];
    EXPECT_TRUE(samePoints(rows(g.faceCentroid, p.start, p.start + p.size),
                           rows(gr.faceCentroid, pr.start, pr.start + pr.size), "face centroids of " + names[s], tol));
  }
}

/// Volume-preserving shear of the skewed fixture (same as skew() in make_mesh_fixtures.py).
std::array<double, 3> skew(std::array<double, 3> p) {
  return {p[0] + 0.4 * p[1] + 0.2 * p[2], p[1] + 0.3 * p[2], p[2]};
}

/// 1-based number of the first line of `path` that starts with `prefix`, 0 if none.
int lineStartingWith(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.rfind(prefix, 0) == 0) return n;
  return 0;
}

int lineCount(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) ++n;
  return n;
}

/// The InputError message `read` throws (fails the test if it throws nothing or something else).
std::string errorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const mfsi::InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected mfsi::InputError, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected mfsi::InputError, nothing was thrown";
  return "";
}

#define EXPECT_HAS(msg, part) EXPECT_NE((msg).find(part), std::string::npos) << "'" << (part) << "' not in: " << (msg)

}  // namespace

// box.msh: scrambled by the fixture script; gmsh_box.msh: written by Gmsh itself.
TEST(GmshReader, BoxMatchesTheBlockGenerator) {
  const auto ref = referenceBox({0, 0, 0}, {1, 0.5, 0.25}, {4, 2, 2}, {1, 1, 1}, kNames);
  for (const std::string file : {"box.msh", "gmsh_box.msh"}) {
    SCOPED_TRACE(file);
    const auto in = mfsi::readGmsh(meshPath(file));
    EXPECT_EQ(in.source, meshPath(file));
    EXPECT_EQ(in.points.size(), 5u * 3u * 3u) << "sparse tags compacted, no unused node kept";
    const auto mesh = mfsi::buildHexMesh(in);
    // Gmsh's own extrusion places the x = 0.5 nodes at 0.4999999999986921: 1e-11 for its file.
    expectSameMesh(mesh, ref, kNames, kNames, file == "box.msh" ? 1e-12 : 1e-11);
    for (const auto& p : mesh.patches()) EXPECT_EQ(p.kind, mfsi::PatchKind::Patch) << p.name;
  }
}

// A physical surface of internal faces is a baffle: the pump's membrane between its two chambers.
TEST(GmshReader, InternalFaceGroupIsABaffle) {
  const auto in = mfsi::readGmsh(meshPath("vad_small.msh"));
  ASSERT_EQ(in.baffles.size(), 1u);
  EXPECT_EQ(in.baffles[0].name, "membrane");
  EXPECT_EQ(in.baffles[0].faces.size(), 48u);
  for (const auto& p : in.patches) EXPECT_NE(p.name, "membrane");
  const auto mesh = mfsi::buildHexMesh(in);
  const int master = mesh.findPatch("membrane_master"), slave = mesh.findPatch("membrane_slave");
  ASSERT_GE(master, 0);
  ASSERT_GE(slave, 0);
  EXPECT_EQ(mesh.patches()[master].size, 48);
  EXPECT_EQ(mesh.patches()[slave].size, 48);
  EXPECT_EQ(mesh.nCells(), 144);
  // The file's node order makes the normal +z: out of the blood (lower) side, the master side.
  const mfsi::MeshGeometry geo = mfsi::allocateGeometry(mesh);
  mfsi::computeGeometry(mfsi::ExecSpace(), mesh, geo);
  auto sf = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), geo.faceArea);
  auto cc = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), geo.cellCentroid);
  auto fc = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), geo.faceCentroid);
  auto own = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), mesh.faceOwner());
  for (const int side : {master, slave}) {
    const auto& m = mesh.patches()[side];
    for (mfsi::lid_t f = m.start; f < m.start + m.size; ++f) {
      // Master faces point up out of the blood cells below them; slave faces down out of the air cells.
      EXPECT_GT(side == master ? sf(f, 2) : -sf(f, 2), 0) << "face " << f;
      EXPECT_EQ(cc(own(f), 2) < fc(f, 2), side == master) << "face " << f;
    }
  }
}

// box.polyMesh: scrambled by the fixture script; openfoam_box: written by OpenFOAM's blockMesh.
TEST(PolyMeshReader, BoxMatchesTheBlockGenerator) {
  const auto ref = referenceBox({0, 0, 0}, {1, 0.5, 0.25}, {4, 2, 2}, {1, 1, 1}, kNames);
  for (const std::string dir : {"box.polyMesh", "openfoam_box/constant/polyMesh"}) {
    SCOPED_TRACE(dir);
    const auto mesh = mfsi::buildHexMesh(mfsi::readPolyMesh(meshPath(dir)));
    expectSameMesh(mesh, ref, kNames, kNames);
    // Patch order and kinds come from the boundary file.
    const mfsi::PatchKind kinds[6] = {mfsi::PatchKind::Patch,    mfsi::PatchKind::Patch, mfsi::PatchKind::Wall,
                                      mfsi::PatchKind::Symmetry, mfsi::PatchKind::Empty, mfsi::PatchKind::Symmetry};
    for (int s = 0; s < 6; ++s) {
      EXPECT_EQ(mesh.patches()[s].name, kNames[s]);
      EXPECT_EQ(mesh.patches()[s].kind, kinds[s]) << kNames[s];
    }
  }
}

TEST(GmshReader, UnstructuredCylinderWrittenByGmsh) {
  // Gmsh split a tetrahedral mesh of a cylinder (radius 0.5, height 0.5) into hexahedra.
  const std::string file = meshPath("gmsh_cylinder.msh");
  // Count the file's hexahedra independently: element blocks "3 <entity> 5 <count>".
  long long hexes = 0;
  {
    std::ifstream in(file);
    std::string line;
    bool inElements = false;
    while (std::getline(in, line)) {
      if (line.rfind("$Elements", 0) == 0) inElements = true;
      int dim = 0, entity = 0, type = 0;
      long long n = 0;
      char extra = 0;
      if (inElements && std::sscanf(line.c_str(), "%d %d %d %lld %c", &dim, &entity, &type, &n, &extra) == 4 &&
          dim == 3 && type == 5)
        hexes += n;
    }
  }
  ASSERT_GT(hexes, 100);
  const auto mesh = mfsi::buildHexMesh(mfsi::readGmsh(file));
  EXPECT_EQ(mesh.nCells(), hexes);
  ASSERT_EQ(mesh.patches().size(), 3u) << "every boundary face is in a physical group";

  auto g = mfsi::allocateGeometry(mesh);
  mfsi::computeGeometry(mfsi::ExecSpace(), mesh, g);
  const auto q = mfsi::computeQuality(mfsi::ExecSpace(), mesh, g);
  EXPECT_GT(q.minScaledJacobian, 0.0);
  // Boundary nodes lie on the (convex) cylinder, so the mesh fills slightly less than it.
  const double r = 0.5, h = 0.5, pi = 3.14159265358979323846;
  EXPECT_LT(q.totalVolume, pi * r * r * h);
  EXPECT_GT(q.totalVolume, 0.95 * pi * r * r * h);

  // Each patch is on its surface with outward normals; top and bottom areas are the same polygon.
  auto area = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceArea);
  auto centre = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), g.faceCentroid);
  double capArea[2] = {0, 0};
  for (const std::string name : {"top", "bottom", "wall"}) {
    const auto& p = mesh.patches()[mesh.patchIndex(name)];
    ASSERT_GT(p.size, 0) << name;
    for (int f = p.start; f < p.start + p.size; ++f) {
      if (name == "wall") {
        const double radial = area(f, 0) * centre(f, 0) + area(f, 1) * centre(f, 1);
        ASSERT_GT(radial, 0.0) << "wall face " << f << " points inwards";
        ASSERT_TRUE(near(std::hypot(centre(f, 0), centre(f, 1)), r, Tol{0.05, 0}, "wall face radius"));
      } else {
        const int cap = name == "top" ? 0 : 1;
        ASSERT_TRUE(near(centre(f, 2), cap == 0 ? h : 0.0, Tol{1e-12, 0}, name + " face height"));
        ASSERT_GT(cap == 0 ? area(f, 2) : -area(f, 2), 0.0) << name << " face " << f << " points inwards";
        capArea[cap] += std::abs(area(f, 2));
      }
    }
  }
  EXPECT_TRUE(near(capArea[0], capArea[1], Tol{0, 1e-12}, "top vs bottom area"));
  EXPECT_LT(capArea[0], pi * r * r);
  EXPECT_GT(capArea[0], 0.9 * pi * r * r);
}

TEST(Readers, GradedSkewedBoxMatchesTheShearedBlockGenerator) {
  const auto ref = referenceBox({0, 0, 0}, {1, 0.5, 0.25}, {5, 3, 2}, {2.0, 0.5, 1.0}, kNames, skew);
  auto gr = mfsi::allocateGeometry(ref);
  mfsi::computeGeometry(mfsi::ExecSpace(), ref, gr);
  const auto qr = mfsi::computeQuality(mfsi::ExecSpace(), ref, gr);
  // The shear keeps the volume and makes the cells non-orthogonal: a non-trivial comparison.
  ASSERT_TRUE(near(qr.totalVolume, 0.125, Tol{0, 1e-13}, "sheared volume"));
  ASSERT_GT(qr.maxNonOrthogonality, 10.0);
  ASSERT_LT(qr.minScaledJacobian, 0.95);

  std::array<std::string, 6> gmshNames = kNames;
  gmshNames[5] = "patch16";  // the front side is a physical group without a name
  expectSameMesh(mfsi::buildHexMesh(mfsi::readGmsh(meshPath("skewed.msh"))), ref, gmshNames, kNames);
  expectSameMesh(mfsi::buildHexMesh(mfsi::readPolyMesh(meshPath("skewed.polyMesh"))), ref, kNames, kNames);
}

TEST(PolyMeshReader, FacesPointingIntoTheirOwnerStillGiveRightHandedCells) {
  // Mirrored points with unchanged faces: the fixture's "left" side now lies at x = 0.
  const auto mesh = mfsi::buildHexMesh(mfsi::readPolyMesh(meshPath("mirrored.polyMesh")));
  const auto ref = referenceBox({-1, 0, 0}, {0, 0.5, 0.25}, {4, 2, 2}, {1, 1, 1}, kNames);
  expectSameMesh(mesh, ref, {"right", "left", "bottom", "top", "back", "front"}, kNames);
}

TEST(GmshReader, BadFilesNameFileLineAndDefect) {
  {
    const std::string f = meshPath("bad_tet.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":" + std::to_string(lineStartingWith(f, "3 3 6 12 13")) + ": non-hex cell");
    EXPECT_HAS(msg, "element 3 is a 4-node tetrahedron");
  }
  {
    const std::string f = meshPath("bad_inverted.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":" + std::to_string(lineStartingWith(f, "42 ")) + ": element 42");
    EXPECT_HAS(msg, "inverted");
  }
  {
    const std::string f = meshPath("bad_truncated.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":" + std::to_string(lineCount(f)) + ": unexpected end of file");
  }
  {
    const std::string f = meshPath("bad_number.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":" + std::to_string(lineStartingWith(f, "2.0 1.O")) + ": expected a node coordinate");
    EXPECT_HAS(msg, "'1.O'");
  }
  {
    const std::string f = meshPath("bad_node_tag.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":" + std::to_string(lineStartingWith(f, "2 2 3 6 5")) + ": element 2");
    EXPECT_HAS(msg, "unknown node tag 99");
  }
  {
    const std::string f = meshPath("bad_version.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":2: MSH format version 2.2 is not supported");
  }
  {
    const std::string f = meshPath("bad_binary.msh");
    const std::string msg = errorOf([&] { mfsi::readGmsh(f); });
    EXPECT_HAS(msg, f + ":2: binary MSH files are not supported");
  }
  {
    const std::string f = meshPath("no_such_file.msh");
    EXPECT_HAS(errorOf([&] { mfsi::readGmsh(f); }), f + ": cannot open");
  }
}

TEST(PolyMeshReader, BadMeshesNameFileAndDefect) {
  {
    const std::string d = meshPath("bad_prism.polyMesh");
    const std::string msg = errorOf([&] { mfsi::readPolyMesh(d); });
    // The first 3-vertex face of the file (a triangle of the prism, cell 1).
    std::ifstream in(d + "/faces");
    std::string line;
    int first = 0;
    for (int n = 1; std::getline(in, line) && first == 0; ++n)
      if (line.rfind("3(", 0) == 0) first = n;
    ASSERT_GT(first, 0);
    EXPECT_HAS(msg, d + "/faces:" + std::to_string(first) + ": non-hex cell 1");
    EXPECT_HAS(msg, "has 3 vertices");
  }
  {
    const std::string d = meshPath("bad_binary.polyMesh");
    const std::string msg = errorOf([&] { mfsi::readPolyMesh(d); });
    EXPECT_HAS(msg, d + "/points:" + std::to_string(lineStartingWith(d + "/points", "    format")) +
                        ": format 'binary' is not supported");
  }
  {
    const std::string d = meshPath("no_such.polyMesh");
    EXPECT_HAS(errorOf([&] { mfsi::readPolyMesh(d); }), d + "/points: cannot open");
  }
}

// Corrupt sizes and labels in a copy of box.polyMesh: each must name the file, the line and the
// entry instead of sizing arrays from them (a label of 2e9 used to allocate 8 GB, a list size of
// 2e9 to reserve 48 GB).
namespace {

/// A copy of box.polyMesh in a scratch folder, with lines of file `name` replaced: {1-based line, text}.
std::string corruptedBox(const std::string& tag, const std::string& name,
                         const std::vector<std::pair<int, std::string>>& edits) {
  const std::string dir = mfsi::test::freshDir("polymesh_" + tag);
  for (const auto& e : std::filesystem::directory_iterator(meshPath("box.polyMesh")))
    std::filesystem::copy_file(e.path(), dir + "/" + e.path().filename().string());
  std::vector<std::string> lines;
  {
    std::ifstream in(dir + "/" + name);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  for (const auto& [line, text] : edits) {
    EXPECT_TRUE(line >= 1 && line <= static_cast<int>(lines.size())) << name << ":" << line;
    if (line >= 1 && line <= static_cast<int>(lines.size())) lines[line - 1] = text;
  }
  std::ofstream out(dir + "/" + name);
  for (const auto& l : lines) out << l << "\n";
  return dir;
}

/// 1-based line of the first entry of the list of `path` (the line after its "(").
int firstEntryLine(const std::string& path) { return lineStartingWith(path, "(") + 1; }

}  // namespace

TEST(PolyMeshReader, HugeLabelsAndSizesAreRefusedBeforeAllocating) {
  const std::string owner = meshPath("box.polyMesh/owner");
  const int entry5 = firstEntryLine(owner) + 5;
  {
    const std::string d = corruptedBox("owner_label", "owner", {{entry5, "2000000000"}});
    EXPECT_HAS(errorOf([&] { mfsi::readPolyMesh(d); }),
               d + "/owner:" + std::to_string(entry5) +
                   ": entry 5: cell label 2000000000 is out of range [0, 16): the header's note gives nCells 16");
  }
  {
    // Without the header's note, the faces bound the cells: 68 faces, at most 34 cells.
    const int note = lineStartingWith(owner, "    note");
    ASSERT_GT(note, 0);
    const std::string d = corruptedBox("owner_label_no_note", "owner", {{note, ""}, {entry5, "2147483647"}});
    EXPECT_HAS(
        errorOf([&] { mfsi::readPolyMesh(d); }),
        d + "/owner:" + std::to_string(entry5) +
            ": entry 5: cell label 2147483647 is out of range [0, 34): the mesh has 68 faces, so at most 34 cells");
  }
  {
    const std::string neighbour = meshPath("box.polyMesh/neighbour");
    const int first = firstEntryLine(neighbour);
    const std::string d = corruptedBox("neighbour_label", "neighbour", {{first, "-7"}});
    EXPECT_HAS(errorOf([&] { mfsi::readPolyMesh(d); }),
               d + "/neighbour:" + std::to_string(first) + ": entry 0: cell label -7 is out of range [0, 16)");
  }
  {
    const std::string points = meshPath("box.polyMesh/points");
    const int size = firstEntryLine(points) - 2;
    const std::string d = corruptedBox("points_size", "points", {{size, "2000000000"}});
    const std::string msg = errorOf([&] { mfsi::readPolyMesh(d); });
    EXPECT_HAS(msg, d + "/points:" + std::to_string(size) +
                        ": the points list announces 2000000000 entries, but the rest "
                        "of the file (");
    EXPECT_HAS(msg, "bytes) holds at most ");
  }
  {
    const int size = firstEntryLine(owner) - 2;
    const std::string d = corruptedBox("owner_size", "owner", {{size, "-3"}});
    EXPECT_HAS(
        errorOf([&] { mfsi::readPolyMesh(d); }),
        d + "/owner:" + std::to_string(size) + ": the owner list announces -3 entries, but a size cannot be negative");
  }
  {
    const std::string boundary = meshPath("box.polyMesh/boundary");
    const int nFaces = lineStartingWith(boundary, "        nFaces");
    const std::string d = corruptedBox("boundary_size", "boundary", {{nFaces, "        nFaces 9223372036854775807;"}});
    EXPECT_HAS(errorOf([&] { mfsi::readPolyMesh(d); }), "nFaces 9223372036854775807) runs past the 68 faces");
  }
}
