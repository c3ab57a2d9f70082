// Membrane surfaces from outside the generators: the master side of a fluid-mesh baffle (counts,
// area, orientation, node and face correspondence with the fluid mesh; an exact large-strain patch
// test on a graded baffle; a pressure-loaded clamped square identical to the generator's) and Gmsh
// 4.1 surface files (tests/data/meshes/membrane_*.msh from scripts/make_membrane_fixtures.py:
// quads, triangles, physical surface selection, line groups as node sets, errors with file:line).
#include "support/Approx.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "structure/membrane/MembraneMeshImport.hpp"
#include "structure/membrane/MembraneSolver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace mfsi;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

std::string meshFile(const std::string& name) { return std::string(MFSI_TEST_DATA_DIR) + "/meshes/" + name; }

/// 1-based number of the first line of `path` that starts with `prefix` (0: none).
int lineStartingWith(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.compare(0, prefix.size(), prefix) == 0) return n;
  return 0;
}

/// Unit box around the plane z = 0 with an 8 x 8 x 2 grid and the baffle "sail" on
/// [0.25, 0.75]^2: 4 x 4 master faces.
HexMesh boxWithSail() {
  BlockMeshSpec spec = boxSpec({0, 0, -0.5}, {1, 1, 0.5}, {8, 8, 2});
  BaffleRect sail;
  sail.name = "sail";
  sail.axis = 2;
  sail.position = 0;
  sail.min = {0.25, 0.25, 0};
  sail.max = {0.75, 0.75, 0};
  spec.baffles.push_back(sail);
  return buildHexMesh(generateBlockMesh(spec));
}

/// Clamped, pre-tensioned membrane under uniform follower pressure; displacement per node.
std::vector<std::array<double, 3>> solvePressure(const MembraneMesh& mesh, const std::vector<lid_t>& clamped) {
  MembraneOptions opt;
  opt.material = {1e6, 0.3, 1e-3, 0, 10.0};  // E, nu, h, rho, T0 (N/m)
  opt.tolerance = 1e-12;
  opt.newton.cgRelTol = 1e-13;
  MembraneBoundary bc;
  bc.clamps.push_back({clamped, {}, {}});
  MembraneLoads loads;
  loads.pressure = 40.0;
  MembraneSolver solver(mesh, opt, bc, loads);
  const MembraneSolveReport rep = solver.solveStatic();
  EXPECT_TRUE(rep.converged) << mesh.source() << ": relative residual " << rep.relativeResidual;
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), solver.results().displacement);
  std::vector<std::array<double, 3>> out(mesh.nNodes());
  for (lid_t n = 0; n < mesh.nNodes(); ++n) out[n] = {u(n, 0), u(n, 1), u(n, 2)};
  return out;
}

/// Same problem on two meshes of the same nodes (any numbering): displacements must agree node
/// by node, matched by reference position. Returns the largest deflection (to check it is not 0).
double expectSameSolution(const MembraneMesh& a, const std::vector<lid_t>& clampA, const MembraneMesh& b,
                          const std::vector<lid_t>& clampB) {
  EXPECT_EQ(a.nNodes(), b.nNodes());
  const auto ua = solvePressure(a, clampA);
  const auto ub = solvePressure(b, clampB);
  double wmax = 0;
  for (const auto& u : ub) wmax = std::max(wmax, std::abs(u[2]));
  double maxDiff = 0;
  for (lid_t n = 0; n < a.nNodes(); ++n) {
    const lid_t m = b.nearestNode(a.hostPoints()[n]);
    for (int k = 0; k < 3; ++k) {
      maxDiff = std::max(maxDiff, std::abs(ua[n][k] - ub[m][k]));
      EXPECT_TRUE(near(a.hostPoints()[n][k], b.hostPoints()[m][k], Tol{1e-14, 0}, "node position"));
      EXPECT_TRUE(near(ua[n][k], ub[m][k], Tol{1e-10 * wmax, 0},
                       a.source() + " vs " + b.source() + ": u" + "xyz"[k] + " of node " + std::to_string(n)));
    }
  }
  std::printf("%s vs %s: max |u| difference %.3e (max deflection %.6e)\n", a.source().c_str(), b.source().c_str(),
              maxDiff, wmax);
  return wmax;
}

}  // namespace

TEST(MembraneImport, BaffleGivesMasterQuadsAndFluidNodeMap) {
  const HexMesh fluid = boxWithSail();
  const FluidSurfaceMembraneInput in = membraneMeshFromBaffle(fluid, "sail");
  const MembraneMesh mesh = buildMembraneMesh(in.mesh);
  EXPECT_EQ(mesh.nElements(), 16);
  EXPECT_EQ(mesh.nQuads(), 16);
  EXPECT_EQ(mesh.nNodes(), 25);
  EXPECT_TRUE(near(mesh.referenceArea(), 0.25, Tol{1e-14, 0}, "area"));
  ASSERT_EQ(mesh.boundaryLoops().size(), 1u);
  EXPECT_EQ(mesh.boundaryLoops()[0].size(), 16u);
  ASSERT_TRUE(mesh.hasNodeSet("boundary"));
  ASSERT_TRUE(mesh.hasNodeSet("centre"));
  EXPECT_EQ(mesh.nodeSet("boundary").size(), 16u);
  for (lid_t n : mesh.nodeSet("boundary")) {
    const auto& x = mesh.hostPoints()[n];
    EXPECT_TRUE(std::abs(std::abs(x[0] - 0.5) - 0.25) < 1e-14 || std::abs(std::abs(x[1] - 0.5) - 0.25) < 1e-14)
        << "boundary node " << n << " at (" << x[0] << ", " << x[1] << ") is not on the sail's edge";
  }
  // The membrane normal is the baffle's (+z).
  for (const auto& nrm : mesh.hostNodeNormals()) EXPECT_TRUE(near(nrm[2], 1.0, Tol{1e-14, 0}, "normal z"));

  // Node correspondence: same positions, distinct fluid nodes; faces map node for node.
  ASSERT_EQ(in.fluidNode.size(), 25u);
  auto fx = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.referencePoints());
  auto faces = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.faceNodes());
  auto facePatch = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.facePatch());
  std::vector<mfsi::gid_t> sortedFluid = in.fluidNode;
  std::sort(sortedFluid.begin(), sortedFluid.end());
  EXPECT_TRUE(std::adjacent_find(sortedFluid.begin(), sortedFluid.end()) == sortedFluid.end());
  for (lid_t n = 0; n < mesh.nNodes(); ++n)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(mesh.hostPoints()[n][k], fx(in.fluidNode[n], k)) << "node " << n;
  const int master = fluid.patchIndex("sail_master"), slave = fluid.patchIndex("sail_slave");
  ASSERT_EQ(in.masterFace.size(), 16u);
  ASSERT_EQ(in.slaveFace.size(), 16u);
  for (lid_t e = 0; e < mesh.nElements(); ++e) {
    EXPECT_EQ(facePatch(in.masterFace[e]), master);
    EXPECT_EQ(facePatch(in.slaveFace[e]), slave);
    std::array<lid_t, 4> m, s;
    for (int a = 0; a < 4; ++a) {
      EXPECT_EQ(in.fluidNode[mesh.hostElements()[e][a]], faces(in.masterFace[e], a)) << "element " << e;
      EXPECT_EQ(in.masterFaceNodes[e][a], faces(in.masterFace[e], a)) << "element " << e;
      EXPECT_EQ(in.slaveFaceNodes[e][a], faces(in.slaveFace[e], a)) << "element " << e;
      m[a] = faces(in.masterFace[e], a);
      s[a] = faces(in.slaveFace[e], a);
    }
    std::sort(m.begin(), m.end());
    std::sort(s.begin(), s.end());
    EXPECT_EQ(m, s) << "element " << e << ": master and slave faces must share their nodes";
  }

  try {
    membraneMeshFromBaffle(fluid, "sial");
    ADD_FAILURE() << "an unknown baffle must throw";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("sail"), std::string::npos) << err.what();
  }
}

// A graded baffle on the plane x = 0 (normal +x): the boundary follows x = F X (in-plane stretch
// and shear of y, z); every element must carry the exact uniform PK2 stress of that strain.
TEST(MembraneImport, GradedBafflePassesThePatchTest) {
  BlockMeshSpec spec = boxSpec({-0.5, 0, 0}, {0.5, 1, 0.8}, {2, 5, 4});
  spec.blocks[0].grading = {1, 2.5, 0.4};
  BaffleRect wall;
  wall.name = "wall";
  wall.axis = 0;
  wall.position = 0;
  wall.min = {0, 0, 0};
  wall.max = {0, 1, 0.8};
  spec.baffles.push_back(wall);
  const HexMesh fluid = buildHexMesh(generateBlockMesh(spec));
  const MembraneMesh mesh = buildMembraneMesh(membraneMeshFromBaffle(fluid, "wall").mesh);
  ASSERT_EQ(mesh.nElements(), 20);
  ASSERT_EQ(mesh.nNodes(), 30);
  EXPECT_TRUE(near(mesh.referenceArea(), 0.8, Tol{1e-14, 0}, "area"));
  for (const auto& nrm : mesh.hostNodeNormals()) EXPECT_TRUE(near(nrm[0], 1.0, Tol{1e-14, 0}, "normal x"));

  const double E = 2e5, nu = 0.35, h = 0.01, T0 = 12.0;
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(1, 1) = 1.10;
  F(1, 2) = 0.05;
  F(2, 1) = 0.02;
  F(2, 2) = 1.04;
  MembraneClamp clamp;
  clamp.nodes = mesh.nodeSet("boundary");
  for (lid_t n : clamp.nodes) {
    const auto& X = mesh.hostPoints()[n];
    const Eigen::Vector3d x = F * Eigen::Vector3d(X[0], X[1], X[2]);
    clamp.offsets.push_back({x[0] - X[0], x[1] - X[1], x[2] - X[2]});
  }
  MembraneBoundary bc;
  bc.clamps.push_back(clamp);
  MembraneOptions opt;
  opt.material = {E, nu, h, 0, T0};
  opt.tolerance = 1e-11;
  MembraneSolver solver(mesh, opt, bc);
  const MembraneSolveReport rep = solver.solveStatic();
  ASSERT_TRUE(rep.converged) << "relative residual " << rep.relativeResidual;

  // Exact PK2 stress in the (y, z) basis; its principal values are basis-independent.
  const Eigen::Matrix2d F2 = F.bottomRightCorner<2, 2>();
  const Eigen::Matrix2d Eg = 0.5 * (F2.transpose() * F2 - Eigen::Matrix2d::Identity());
  const double c = E / (1 - nu * nu);
  const Eigen::Matrix2d S =
      c * ((1 - nu) * Eg + nu * Eg.trace() * Eigen::Matrix2d::Identity()) + T0 / h * Eigen::Matrix2d::Identity();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(S);
  const double s1 = eig.eigenvalues()(1), s2 = eig.eigenvalues()(0);
  const MembraneResults res = solver.results();
  auto p1 = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.principal1);
  auto p2 = Kokkos::create_mirror_view_and_copy(HostSpace(), res.elements.principal2);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), res.displacement);
  for (lid_t e = 0; e < mesh.nElements(); ++e) {
    ASSERT_TRUE(near(p1(e), s1, Tol{1e-8 * s1, 0}, "s1 of element " + std::to_string(e)));
    ASSERT_TRUE(near(p2(e), s2, Tol{1e-8 * s1, 0}, "s2 of element " + std::to_string(e)));
  }
  for (lid_t n = 0; n < mesh.nNodes(); ++n) {
    const auto& X = mesh.hostPoints()[n];
    const Eigen::Vector3d x = F * Eigen::Vector3d(X[0], X[1], X[2]);
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(near(u(n, k), x[k] - X[k], Tol{1e-10, 0}, "u of node " + std::to_string(n)));
  }
}

TEST(MembraneImport, BafflePressureSolveMatchesTheRectangleGenerator) {
  const MembraneMesh sail = buildMembraneMesh(membraneMeshFromBaffle(boxWithSail(), "sail").mesh);
  MembraneRectangleSpec rect;
  rect.origin = {0.25, 0.25, 0};
  rect.lx = rect.ly = 0.5;
  rect.nx = rect.ny = 4;
  const MembraneMesh gen = buildMembraneMesh(generateRectangleMesh(rect));
  const double wmax = expectSameSolution(sail, sail.nodeSet("boundary"), gen, gen.nodeSet("boundary"));
  EXPECT_GT(wmax, 1e-3) << "the pressure must deflect the membrane visibly";
}

TEST(MembraneImport, GmshQuadSurfaceWithGroups) {
  const std::string path = meshFile("membrane_square_quads.msh");
  const MembraneMesh all = buildMembraneMesh(readGmshSurface(path));
  EXPECT_EQ(all.nElements(), 20);
  EXPECT_EQ(all.nNodes(), 34);
  EXPECT_TRUE(near(all.referenceArea(), 2.0, Tol{1e-14, 0}, "area of both surfaces"));
  EXPECT_EQ(all.boundaryLoops().size(), 2u);

  for (const std::string group : {"membrane", "1"}) {
    const MembraneMesh mesh = buildMembraneMesh(readGmshSurface(path, group));
    EXPECT_EQ(mesh.nElements(), 16) << group;
    EXPECT_EQ(mesh.nQuads(), 16) << group;
    EXPECT_EQ(mesh.nNodes(), 25) << group;
    EXPECT_TRUE(near(mesh.referenceArea(), 1.0, Tol{1e-14, 0}, "area of 'membrane'"));
    EXPECT_EQ(mesh.nodeSet("clamped"), mesh.boundaryNodes()) << "the four sides are the free edge";
    EXPECT_EQ(mesh.nodeSet("xmin").size(), 5u);
    for (lid_t n : mesh.nodeSet("xmin")) EXPECT_EQ(mesh.hostPoints()[n][0], 0.0);
    for (const auto& nrm : mesh.hostNodeNormals()) EXPECT_TRUE(near(nrm[2], 1.0, Tol{1e-14, 0}, "normal z"));
  }
  const MembraneMesh other = buildMembraneMesh(readGmshSurface(path, "other"));
  EXPECT_EQ(other.nElements(), 4);
  EXPECT_EQ(other.nNodes(), 9);
  EXPECT_FALSE(other.hasNodeSet("clamped")) << "a line group with no node on the surface is dropped";

  const MembraneMesh mesh = buildMembraneMesh(readGmshSurface(path, "membrane"));
  MembraneRectangleSpec rect;
  rect.nx = rect.ny = 4;
  const MembraneMesh gen = buildMembraneMesh(generateRectangleMesh(rect));
  const double wmax = expectSameSolution(mesh, mesh.nodeSet("clamped"), gen, gen.nodeSet("boundary"));
  EXPECT_GT(wmax, 1e-3);
}

TEST(MembraneImport, GmshTriangleSurface) {
  const MembraneMesh mesh = buildMembraneMesh(readGmshSurface(meshFile("membrane_square_tris.msh"), "membrane"));
  EXPECT_EQ(mesh.nElements(), 32);
  EXPECT_EQ(mesh.nTriangles(), 32);
  EXPECT_EQ(mesh.nNodes(), 25);
  EXPECT_TRUE(near(mesh.referenceArea(), 1.0, Tol{1e-14, 0}, "area"));
  EXPECT_EQ(mesh.nodeSet("clamped").size(), 16u);
  MembraneRectangleSpec rect;
  rect.nx = rect.ny = 4;
  rect.type = MembraneElementType::Tri3;
  const MembraneMesh gen = buildMembraneMesh(generateRectangleMesh(rect));
  const double wmax = expectSameSolution(mesh, mesh.nodeSet("clamped"), gen, gen.nodeSet("boundary"));
  EXPECT_GT(wmax, 1e-3);
}

TEST(MembraneImport, GmshErrorsNameFileAndLine) {
  struct Case {
    std::string file, group, linePrefix, text;
  };
  const std::vector<Case> cases = {
      {"membrane_square_quads.msh", "sails", "$PhysicalNames", "no physical surface group 'sails'"},
      {"membrane_bad_type.msh", "", "77 ", "6-node triangle"},
      {"membrane_bad_line.msh", "", "88 ", "3-node line"},
      {"membrane_bad_node.msh", "", "5 999 ", "unknown node tag 999"},
      {"membrane_bad_truncated.msh", "", "", "truncated"},
  };
  for (const auto& c : cases) {
    const std::string path = meshFile(c.file);
    try {
      readGmshSurface(path, c.group);
      ADD_FAILURE() << c.file << " must be rejected";
    } catch (const InputError& err) {
      const std::string msg = err.what();
      std::printf("%s\n", msg.c_str());
      EXPECT_EQ(err.where().file, path) << msg;
      EXPECT_NE(msg.find(c.text), std::string::npos) << msg;
      if (!c.linePrefix.empty()) {
        // The group list sits on the line after $PhysicalNames (its count).
        const int expected = lineStartingWith(path, c.linePrefix) + (c.linePrefix[0] == '$' ? 1 : 0);
        ASSERT_GT(expected, 1);
        EXPECT_EQ(err.where().line, expected) << msg;
      } else {
        // Truncated: the last line of the file (the element that was cut).
        std::ifstream in(path);
        int lines = 0;
        for (std::string l; std::getline(in, l);) ++lines;
        EXPECT_EQ(err.where().line, lines) << msg;
      }
    }
  }
}
