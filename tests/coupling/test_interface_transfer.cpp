// The matching membrane <-> fluid interface: maps of a membrane cut from a one-sided patch and from
// a baffle, conservative loads (the membrane's external force equals sum_f p_f S_f to round-off,
// flat and deformed), displacements landing on the right fluid nodes, face wall velocities.
#include "coupling/interface/MembraneInterface.hpp"

#include "support/Approx.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "structure/membrane/MembraneSolver.hpp"

#include <gtest/gtest.h>

#include <cmath>

using mfsi::lid_t;
using mfsi::real;
using mfsi::test::near;
using mfsi::test::Tol;
namespace cpl = mfsi::coupling;

namespace {

/// A box [0,2] x [0,1] x [0,1.5] of 4 x 3 x 3 cells with its bottom (y = 0) patch named "bottom";
/// with `baffle`, a baffle "sail" on the plane x = 1 over the whole cross-section.
mfsi::HexMesh box(bool baffle) {
  mfsi::BlockMeshSpec spec = mfsi::boxSpec({0, 0, 0}, {2, 1, 1.5}, {4, 3, 3});
  spec.blocks[0].patches = {"sides", "sides", "bottom", "sides", "sides", "sides"};
  if (baffle) spec.baffles.push_back({"sail", 0, 1.0, {0, 0, 0}, {0, 1, 1.5}});
  return mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
}

/// A boundary-face pressure field pb(b) = 1 + x + 2 z + 3 y^2 at the face centroids.
mfsi::RealView facePressure(const mfsi::HexMesh& mesh, const mfsi::MeshGeometry& geo) {
  const lid_t nIn = mesh.nInternalFaces(), nB = mesh.nBoundaryFaces();
  mfsi::RealView pb("pb", nB);
  auto h = Kokkos::create_mirror_view(pb);
  auto c = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo.faceCentroid);
  for (lid_t b = 0; b < nB; ++b) h(b) = 1 + c(b + nIn, 0) + 2 * c(b + nIn, 2) + 3 * c(b + nIn, 1) * c(b + nIn, 1);
  Kokkos::deep_copy(pb, h);
  return pb;
}

/// Sum over nodes of the membrane's external force (the residual R = f_ext - f_int with and without
/// the load: internal forces cancel in the difference).
std::array<double, 3> membraneLoadSum(mfsi::MembraneSolver& s, const mfsi::RealView& load) {
  // Own host copies: a mirror of a host View would be the solver's residual itself.
  s.loads().elementPressure = load;
  Kokkos::View<double*, Kokkos::HostSpace> r1("r1", 3 * s.mesh().nNodes()), r0("r0", 3 * s.mesh().nNodes());
  Kokkos::deep_copy(r1, s.residual(0));
  s.loads().elementPressure = mfsi::RealView();
  Kokkos::deep_copy(r0, s.residual(0));
  std::array<double, 3> f{0, 0, 0};
  for (lid_t n = 0; n < s.mesh().nNodes(); ++n)
    for (int k = 0; k < 3; ++k) f[k] += r1(3 * n + k) - r0(3 * n + k);
  return f;
}

mfsi::MembraneOptions material() {
  mfsi::MembraneOptions o;
  o.material = {1e5, 0.3, 1e-3, 1000, 0};
  return o;
}

/// Membrane displacement (a bump along -y, the outward normal, and some in-plane motion), the same on
/// the fluid nodes: the deformed geometry both sides see.
void deform(mfsi::MembraneSolver& s, mfsi::HexMesh& mesh, const cpl::MembraneInterface& iface) {
  const auto& X = s.mesh().hostPoints();
  auto u = Kokkos::create_mirror_view(s.displacement());
  for (lid_t n = 0; n < s.mesh().nNodes(); ++n) {
    const double bump = std::sin(M_PI * X[n][0] / 2) * std::sin(M_PI * X[n][2] / 1.5);
    u(3 * n + 0) = 0.05 * bump;
    u(3 * n + 1) = -0.3 * bump;
    u(3 * n + 2) = 0.02 * X[n][0] * bump;
  }
  Kokkos::deep_copy(s.displacement(), u);
  mfsi::Real3View d("d", mesh.nNodes());
  cpl::interfaceDisplacement(mfsi::ExecSpace(), iface, s.displacement(), d);
  const mfsi::Real3View x = mesh.points();
  const mfsi::ConstReal3View X0 = mesh.referencePoints();
  Kokkos::parallel_for(
      "test::place", mfsi::RangePolicy(mfsi::ExecSpace(), 0, mesh.nNodes()), KOKKOS_LAMBDA(lid_t i) {
        for (int k = 0; k < 3; ++k) x(i, k) = X0(i, k) + d(i, k);
      });
  Kokkos::fence();
}

}  // namespace

TEST(InterfaceTransfer, APatchMembraneMapsOntoTheWallFacesWithTheOutwardNormal) {
  const auto mesh = box(false);
  const auto surf = mfsi::membraneMeshFromPatch(mesh, "bottom");
  EXPECT_EQ(surf.mesh.elements.size(), 4u * 3u);
  EXPECT_EQ(surf.fluidNode.size(), 5u * 4u);
  EXPECT_TRUE(surf.slaveFace.empty());
  EXPECT_EQ(surf.mesh.nodeSets.at("xmin").size(), 4u);
  EXPECT_EQ(surf.mesh.nodeSets.at("zmax").size(), 5u);
  EXPECT_EQ(surf.mesh.nodeSets.count("ymin"), 0u) << "the flat axis has no side sets";
  const auto mm = mfsi::buildMembraneMesh(surf.mesh);
  for (lid_t n = 0; n < mm.nNodes(); ++n) {
    EXPECT_TRUE(near(mm.hostNodeNormals()[n][1], -1.0, Tol{1e-14, 0})) << "node " << n;
    EXPECT_TRUE(near(mm.hostPoints()[n][1], 0.0, Tol{1e-14, 0}));
  }
  EXPECT_THROW(mfsi::membraneMeshFromPatch(mesh, "botom"), mfsi::InputError);
  const auto withBaffle = box(true);
  EXPECT_THROW(mfsi::membraneMeshFromPatch(withBaffle, "sail_master"), mfsi::InputError);
}

TEST(InterfaceTransfer, PatchLoadIsConservativeFlatAndDeformed) {
  auto mesh = box(false);
  auto geo = mfsi::allocateGeometry(mesh);
  mfsi::ExecSpace exec;
  mfsi::computeGeometry(exec, mesh, geo);
  const auto surf = mfsi::membraneMeshFromPatch(mesh, "bottom");
  const auto iface = cpl::makeMembraneInterface(mesh, surf, "bottom", cpl::InterfaceSide::Patch);
  mfsi::MembraneSolver s(mfsi::buildMembraneMesh(surf.mesh), material());
  const mfsi::RealView pb = facePressure(mesh, geo);
  mfsi::RealView load("load", iface.nElements());
  const double outside = 0.25;
  cpl::interfacePressure(exec, iface, pb, outside, 1.0, 0.0, load);
  // Flat: the force is sum (p - outside) S over the bottom faces, S = -y * area.
  auto F = cpl::interfaceForce(exec, iface, mesh.nInternalFaces(), geo.faceArea, load);
  auto f = membraneLoadSum(s, load);
  EXPECT_GT(std::abs(F[1]), 1.0);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(f[k], F[k], Tol{1e-13, 1e-13})) << "flat, component " << k;
  EXPECT_TRUE(near(F[0], 0, Tol{1e-13, 0}));
  // Deformed: the membrane integrates the follower pressure on its bilinear elements, the fluid
  // has the same faces moved; the vector areas agree, so the totals do.
  deform(s, mesh, iface);
  mfsi::computeGeometry(exec, mesh, geo);
  F = cpl::interfaceForce(exec, iface, mesh.nInternalFaces(), geo.faceArea, load);
  f = membraneLoadSum(s, load);
  EXPECT_GT(std::abs(F[0]), 1e-3) << "the deformed surface is tilted: some force along x";
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(f[k], F[k], Tol{1e-13, 1e-12})) << "deformed, component " << k;
  // A clamp limits the element pressure.
  cpl::interfacePressure(exec, iface, pb, outside, 2.0, 3.0, load);
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), load);
  double mx = 0;
  for (lid_t e = 0; e < iface.nElements(); ++e) mx = std::max(mx, std::abs(h(e)));
  EXPECT_EQ(mx, 3.0);
}

TEST(InterfaceTransfer, BaffleLoadIsTheNetPressureAndConservative) {
  auto mesh = box(true);
  auto geo = mfsi::allocateGeometry(mesh);
  mfsi::ExecSpace exec;
  mfsi::computeGeometry(exec, mesh, geo);
  const auto surf = mfsi::membraneMeshFromBaffle(mesh, "sail");
  const auto iface = cpl::makeMembraneInterface(mesh, surf, "sail", cpl::InterfaceSide::Baffle);
  ASSERT_EQ(iface.nElements(), 9);
  // Master side 5 + y, slave side 2: pNet = 3 + y on every face pair.
  const lid_t nIn = mesh.nInternalFaces();
  mfsi::RealView pb("pb", mesh.nBoundaryFaces());
  {
    auto h = Kokkos::create_mirror_view(pb);
    auto c = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo.faceCentroid);
    Kokkos::deep_copy(h, 0.0);
    for (std::size_t e = 0; e < surf.masterFace.size(); ++e) {
      h(surf.masterFace[e] - nIn) = 5 + c(surf.masterFace[e], 1);
      h(surf.slaveFace[e] - nIn) = 2;
    }
    Kokkos::deep_copy(pb, h);
  }
  mfsi::RealView load("load", iface.nElements());
  cpl::interfacePressure(exec, iface, pb, 123.0, 1.0, 0.0, load);  // the outside pressure plays no part
  const auto F = cpl::interfaceForce(exec, iface, nIn, geo.faceArea, load);
  // Baffle normal +x, area 1.5, mean of 3 + y over the plane: 3.5.
  EXPECT_TRUE(near(F[0], 3.5 * 1.5, Tol{1e-13, 1e-13}));
  mfsi::MembraneSolver s(mfsi::buildMembraneMesh(surf.mesh), material());
  const auto f = membraneLoadSum(s, load);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(f[k], F[k], Tol{1e-13, 1e-13})) << "component " << k;
}

TEST(InterfaceTransfer, DisplacementsLandOnTheirFluidNodesAndVelocitiesOnTheirFaces) {
  auto mesh = box(false);
  const auto surf = mfsi::membraneMeshFromPatch(mesh, "bottom");
  const auto iface = cpl::makeMembraneInterface(mesh, surf, "bottom", cpl::InterfaceSide::Patch);
  mfsi::MembraneSolver s(mfsi::buildMembraneMesh(surf.mesh), material());
  deform(s, mesh, iface);
  // Every membrane node's deformed position is its fluid node's position.
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
  auto u = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.displacement());
  const auto& X = s.mesh().hostPoints();
  for (lid_t n = 0; n < s.mesh().nNodes(); ++n)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(x(surf.fluidNode[n], k), X[n][k] + u(3 * n + k)) << "node " << n << " component " << k;
  // Face velocity: the mean of the nodal velocities (here v = displacement, linear in nothing: check
  // against a host mean).
  mfsi::Real3View fv("fv", iface.nElements());
  cpl::interfaceFaceVelocity(mfsi::ExecSpace(), iface, s.mesh().elementNodes(), s.displacement(), fv);
  auto hf = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), fv);
  const auto& el = s.mesh().hostElements();
  for (lid_t e = 0; e < iface.nElements(); ++e)
    for (int k = 0; k < 3; ++k) {
      double m = 0;
      for (int a = 0; a < 4; ++a) m += 0.25 * u(3 * el[e][a] + k);
      EXPECT_TRUE(near(hf(e, k), m, Tol{1e-15, 1e-14})) << "face " << e;
    }
}

TEST(InterfaceTransfer, LoadSmoothingKeepsTheTotalForceAndDampsACheckerboard) {
  auto mesh = box(false);
  const auto surf = mfsi::membraneMeshFromPatch(mesh, "bottom");
  // A graded patch would have unequal areas: stretch the reference areas to make them unequal.
  const auto mm = mfsi::buildMembraneMesh(surf.mesh);
  std::vector<real> areas(mm.elementAreas());
  for (std::size_t e = 0; e < areas.size(); ++e) areas[e] *= 1 + 0.5 * (e % 3);
  const auto g = cpl::elementGraph(mm.hostElements(), areas);
  const lid_t ne = mm.nElements();
  mfsi::RealView p("p", ne), work("work", ne);
  auto hp = Kokkos::create_mirror_view(p);
  // Checkerboard on the 4 x 3 grid of faces, plus a mean.
  const auto& X = mm.hostPoints();
  const auto& el = mm.hostElements();
  for (lid_t e = 0; e < ne; ++e) {
    double cx = 0, cz = 0;
    for (int a = 0; a < 4; ++a) {
      cx += 0.25 * X[el[e][a]][0];
      cz += 0.25 * X[el[e][a]][2];
    }
    const int i = static_cast<int>(cx / 0.5), k = static_cast<int>(cz / 0.5);
    hp(e) = 2 + ((i + k) % 2 == 0 ? 1.0 : -1.0);
  }
  Kokkos::deep_copy(p, hp);
  auto totalAndSpread = [&]() {
    Kokkos::View<double*, Kokkos::HostSpace> h("h", ne);
    Kokkos::deep_copy(h, p);
    double t = 0, lo = 1e300, hi = -1e300;
    for (lid_t e = 0; e < ne; ++e) {
      t += areas[e] * h(e);
      lo = std::min(lo, h(e));
      hi = std::max(hi, h(e));
    }
    return std::array<double, 2>{t, hi - lo};
  };
  const auto before = totalAndSpread();
  cpl::smoothInterfacePressure(mfsi::ExecSpace(), g, p, work, 10);
  const auto after = totalAndSpread();
  EXPECT_TRUE(near(after[0], before[0], Tol{1e-13, 1e-14})) << "sum A p kept";
  EXPECT_NEAR(before[1], 2.0, 1e-14);
  EXPECT_LT(after[1], 0.5 * before[1]) << "the checkerboard is damped";
}
