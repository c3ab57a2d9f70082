// Finite-volume building blocks against hand-derivable golds and serial host versions: sparsity,
// matrix assembly and divergence (gather vs scatter vs host), gradients exact for linear fields,
// swept volumes satisfying the space-conservation law, and kernel/View labels.
#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/FvAssembly.hpp"
#include "fluid/FvFaceData.hpp"
#include "fluid/Gradient.hpp"
#include "fluid/MeshFlux.hpp"
#include "support/Approx.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>

using namespace mfsi;
using namespace mfsi::fluid;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

HexMesh distortedBox(bool distort, unsigned seed = 3) {
  auto spec = boxSpec({0, 0, 0}, {1.0, 0.8, 0.6}, {5, 4, 3});
  spec.blocks[0].grading = {2.0, 1.0, 0.7};
  spec.blocks[0].patches = {"a", "b", "c", "d", "e", "f"};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  if (distort) {
    auto pts = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.points());
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int n = 0; n < mesh.nNodes(); ++n) {
      const bool interior = pts(n, 0) > 1e-9 && pts(n, 0) < 1 - 1e-9 && pts(n, 1) > 1e-9 && pts(n, 1) < 0.8 - 1e-9 &&
                            pts(n, 2) > 1e-9 && pts(n, 2) < 0.6 - 1e-9;
      if (interior)
        for (int k = 0; k < 3; ++k) pts(n, k) += 0.03 * u(gen);
    }
    Kokkos::deep_copy(mesh.points(), pts);
  }
  return mesh;
}

template <class V>
auto host(const V& v) {
  return Kokkos::create_mirror_view_and_copy(HostSpace(), v);
}

}  // namespace

TEST(FvKernels, SparsityHasOneEntryPerFaceNeighbourAndTheDiagonal) {
  HexMesh mesh = distortedBox(false);
  const FvSparsity s = buildSparsity(mesh);
  EXPECT_EQ(static_cast<lid_t>(s.colIdx.extent(0)), mesh.nCells() + 2 * mesh.nInternalFaces());
  auto rp = host(s.rowPtr);
  auto ci = host(s.colIdx);
  auto di = host(s.diagIdx);
  auto op = host(s.ownerPos);
  auto np = host(s.neighbourPos);
  auto own = host(mesh.faceOwner());
  auto nei = host(mesh.faceNeighbour());
  for (int c = 0; c < mesh.nCells(); ++c) {
    EXPECT_EQ(ci(di(c)), c);
    for (int k = rp(c) + 1; k < rp(c + 1); ++k) EXPECT_LT(ci(k - 1), ci(k)) << "row " << c << " not sorted";
  }
  for (int f = 0; f < mesh.nInternalFaces(); ++f) {
    EXPECT_EQ(ci(op(f)), nei(f));
    EXPECT_GE(op(f), rp(own(f)));
    EXPECT_LT(op(f), rp(own(f) + 1));
    EXPECT_EQ(ci(np(f)), own(f));
    EXPECT_GE(np(f), rp(nei(f)));
    EXPECT_LT(np(f), rp(nei(f) + 1));
  }
}

TEST(FvKernels, AssemblyGatherMatchesHostAndScatter) {
  HexMesh mesh = distortedBox(true);
  const FvSparsity s = buildSparsity(mesh);
  FaceCoefficients fc = allocateFaceCoefficients(mesh, "test::fc");
  RealView cellDiag("test::cellDiag", mesh.nCells());
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-1, 1);
  auto hod = Kokkos::create_mirror_view(fc.ownerDiag), hnd = Kokkos::create_mirror_view(fc.neighbourDiag),
       hup = Kokkos::create_mirror_view(fc.upper), hlo = Kokkos::create_mirror_view(fc.lower);
  auto hcd = Kokkos::create_mirror_view(cellDiag);
  for (int f = 0; f < mesh.nFaces(); ++f) {
    hod(f) = u(gen);
    hnd(f) = u(gen);
    hup(f) = u(gen);
    hlo(f) = u(gen);
  }
  for (int c = 0; c < mesh.nCells(); ++c) hcd(c) = u(gen);
  Kokkos::deep_copy(fc.ownerDiag, hod);
  Kokkos::deep_copy(fc.neighbourDiag, hnd);
  Kokkos::deep_copy(fc.upper, hup);
  Kokkos::deep_copy(fc.lower, hlo);
  Kokkos::deep_copy(cellDiag, hcd);
  CsrMatrix Ag = makeMatrix(s, "test::Ag"), As = makeMatrix(s, "test::As");
  assembleMatrix(ExecSpace(), mesh, s, fc, cellDiag, Ag, ReductionMode::Gather);
  assembleMatrix(ExecSpace(), mesh, s, fc, cellDiag, As, ReductionMode::Scatter);
  auto g = host(Ag.values), sc = host(As.values);
  // Serial host gold: the same sums in the same order as the gather (cell's faces in CSR order).
  auto rp = host(s.rowPtr), ci = host(s.colIdx), di = host(s.diagIdx);
  auto off = host(mesh.cellFaceOffsets()), cf = host(mesh.cellFaces()), own = host(mesh.faceOwner()),
       nei = host(mesh.faceNeighbour());
  for (int c = 0; c < mesh.nCells(); ++c) {
    double diag = hcd(c);
    for (int e = off(c); e < off(c + 1); ++e) {
      const int f = cf(e);
      diag += own(f) == c ? hod(f) : hnd(f);
      if (f < mesh.nInternalFaces()) {
        const int other = own(f) == c ? nei(f) : own(f);
        int k = rp(c);
        while (ci(k) != other) ++k;
        ASSERT_EQ(g(k), own(f) == c ? hup(f) : hlo(f)) << "off-diagonal of face " << f;
      }
    }
    ASSERT_EQ(g(di(c)), diag) << "diagonal of row " << c;
  }
  for (int k = 0; k < Ag.nnz(); ++k) ASSERT_TRUE(near(sc(k), g(k), Tol{1e-14, 1e-14}, "scatter entry " + std::to_string(k)));
}

TEST(FvKernels, DivergenceGatherIsDeterministicAndMatchesScatter) {
  HexMesh mesh = distortedBox(true);
  Real3View flux("test::flux", mesh.nFaces());
  auto hf = Kokkos::create_mirror_view(flux);
  std::mt19937 gen(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int f = 0; f < mesh.nFaces(); ++f)
    for (int k = 0; k < 3; ++k) hf(f, k) = u(gen);
  Kokkos::deep_copy(flux, hf);
  Real3View a("test::a", mesh.nCells()), b("test::b", mesh.nCells()), c("test::c", mesh.nCells());
  divergence<3>(ExecSpace(), mesh, flux, a, ReductionMode::Gather);
  divergence<3>(ExecSpace(), mesh, flux, b, ReductionMode::Gather);
  divergence<3>(ExecSpace(), mesh, flux, c, ReductionMode::Scatter);
  auto ha = host(a), hb = host(b), hc = host(c);
  auto own = host(mesh.faceOwner()), nei = host(mesh.faceNeighbour());
  std::vector<std::array<double, 3>> gold(mesh.nCells(), {0, 0, 0});
  for (int f = 0; f < mesh.nFaces(); ++f)
    for (int k = 0; k < 3; ++k) {
      gold[own(f)][k] += hf(f, k);
      if (nei(f) >= 0) gold[nei(f)][k] -= hf(f, k);
    }
  for (int i = 0; i < mesh.nCells(); ++i)
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(ha(i, k), hb(i, k)) << "gather must be bitwise reproducible";
      ASSERT_TRUE(near(ha(i, k), gold[i][k], Tol{1e-14, 0}, "gather vs host, cell " + std::to_string(i)));
      ASSERT_TRUE(near(hc(i, k), gold[i][k], Tol{1e-14, 0}, "scatter vs host, cell " + std::to_string(i)));
    }
}

TEST(FvKernels, GradientsAreExactForLinearFields) {
  // Gauss linear: exact on a graded Cartesian mesh (faces are met by the centroid line at their
  // centroid); least squares: exact on any mesh.
  for (bool distort : {false, true}) {
    HexMesh mesh = distortedBox(distort);
    MeshGeometry geo = allocateGeometry(mesh);
    computeGeometry(ExecSpace(), mesh, geo);
    FvFaceData fd = allocateFaceData(mesh);
    computeFaceData(ExecSpace(), mesh, geo, fd);
    const double g[3] = {1.5, -2.0, 0.75};
    auto cc = host(geo.cellCentroid), fc = host(geo.faceCentroid);
    RealView phi("test::phi", mesh.nCells()), phiB("test::phiB", mesh.nBoundaryFaces());
    Real3View u("test::u", mesh.nCells()), uB("test::uB", mesh.nBoundaryFaces());
    auto hp = Kokkos::create_mirror_view(phi), hpb = Kokkos::create_mirror_view(phiB);
    auto hu = Kokkos::create_mirror_view(u), hub = Kokkos::create_mirror_view(uB);
    auto lin = [&](double x, double y, double z) { return 0.3 + g[0] * x + g[1] * y + g[2] * z; };
    for (int c = 0; c < mesh.nCells(); ++c) {
      hp(c) = lin(cc(c, 0), cc(c, 1), cc(c, 2));
      for (int j = 0; j < 3; ++j) hu(c, j) = (j + 1) * hp(c);
    }
    for (int b = 0; b < mesh.nBoundaryFaces(); ++b) {
      const int f = b + mesh.nInternalFaces();
      hpb(b) = lin(fc(f, 0), fc(f, 1), fc(f, 2));
      for (int j = 0; j < 3; ++j) hub(b, j) = (j + 1) * hpb(b);
    }
    Kokkos::deep_copy(phi, hp);
    Kokkos::deep_copy(phiB, hpb);
    Kokkos::deep_copy(u, hu);
    Kokkos::deep_copy(uB, hub);
    for (GradientScheme scheme : {GradientScheme::GaussLinear, GradientScheme::LeastSquares}) {
      if (distort && scheme == GradientScheme::GaussLinear) continue;
      Real3View grad("test::grad", mesh.nCells());
      Tensor3View gradU("test::gradU", mesh.nCells());
      cellGradient(ExecSpace(), scheme, mesh, geo, fd, phi, phiB, grad);
      cellGradient(ExecSpace(), scheme, mesh, geo, fd, u, uB, gradU);
      auto hg = host(grad);
      auto hG = host(gradU);
      for (int c = 0; c < mesh.nCells(); ++c)
        for (int i = 0; i < 3; ++i) {
          ASSERT_TRUE(near(hg(c, i), g[i], Tol{1e-11, 0}, "scalar gradient, cell " + std::to_string(c)));
          for (int j = 0; j < 3; ++j)
            ASSERT_TRUE(near(hG(c, i, j), (j + 1) * g[i], Tol{1e-11, 0}, "vector gradient, cell " + std::to_string(c)));
        }
    }
  }
}

TEST(FvKernels, BoundaryCellGradientUpdateEqualsAFullRecompute) {
  // The solver refreshes only the cells next to the boundary after new boundary values: that must
  // reproduce a full recompute bitwise, and leave cells without boundary faces untouched.
  HexMesh mesh = distortedBox(true);
  MeshGeometry geo = allocateGeometry(mesh);
  computeGeometry(ExecSpace(), mesh, geo);
  FvFaceData fd = allocateFaceData(mesh);
  computeFaceData(ExecSpace(), mesh, geo, fd);
  const IndexView cells = boundaryCells(mesh);
  auto hc = host(cells);
  auto own = host(mesh.faceOwner());
  std::set<int> expected;
  for (int f = mesh.nInternalFaces(); f < mesh.nFaces(); ++f) expected.insert(own(f));
  ASSERT_EQ(hc.extent(0), expected.size());
  ASSERT_TRUE(std::set<int>(hc.data(), hc.data() + hc.extent(0)) == expected);
  ASSERT_LT(static_cast<int>(hc.extent(0)), mesh.nCells());  // 5x4x3 has 6 interior cells

  RealView phi("test::phi", mesh.nCells()), phiB("test::phiB", mesh.nBoundaryFaces());
  auto hp = Kokkos::create_mirror_view(phi), hpb = Kokkos::create_mirror_view(phiB);
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int c = 0; c < mesh.nCells(); ++c) hp(c) = u(gen);
  for (int b = 0; b < mesh.nBoundaryFaces(); ++b) hpb(b) = u(gen);
  Kokkos::deep_copy(phi, hp);
  Kokkos::deep_copy(phiB, hpb);
  for (GradientScheme scheme : {GradientScheme::GaussLinear, GradientScheme::LeastSquares}) {
    Real3View partial("test::partial", mesh.nCells()), full("test::full", mesh.nCells());
    cellGradient(ExecSpace(), scheme, mesh, geo, fd, phi, phiB, partial);
    auto before = Kokkos::create_mirror(partial);  // a copy, also on host backends
    Kokkos::deep_copy(before, partial);
    for (int b = 0; b < mesh.nBoundaryFaces(); ++b) hpb(b) = 3.0 * u(gen);
    Kokkos::deep_copy(phiB, hpb);
    cellGradient(ExecSpace(), scheme, mesh, geo, fd, phi, phiB, partial, cells);
    cellGradient(ExecSpace(), scheme, mesh, geo, fd, phi, phiB, full);
    auto hPart = host(partial), hFull = host(full);
    int changed = 0;
    for (int c = 0; c < mesh.nCells(); ++c)
      for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(hPart(c, i), hFull(c, i)) << "cell " << c << " component " << i;
        if (!expected.count(c)) {
          ASSERT_EQ(hPart(c, i), before(c, i)) << "interior cell " << c;
        }
        changed += hPart(c, i) != before(c, i) ? 1 : 0;
      }
    EXPECT_GT(changed, 0);
  }
}

TEST(FvKernels, GradientStencilEqualsTheFaceFormula) {
  // The solver's contiguous stencil against the face-by-face Gauss formula on a distorted graded
  // mesh, for random scalar and vector fields with random boundary values, over all cells and over
  // the boundary cells alone.
  HexMesh mesh = distortedBox(true, 5);
  MeshGeometry geo = allocateGeometry(mesh);
  computeGeometry(ExecSpace(), mesh, geo);
  FvFaceData fd = allocateFaceData(mesh);
  computeFaceData(ExecSpace(), mesh, geo, fd);
  const GradientStencil st = allocateGradientStencil(mesh);
  computeGradientStencil(ExecSpace(), mesh, geo, fd, st);
  RealView phi("test::phi", mesh.nCells()), phiB("test::phiB", mesh.nBoundaryFaces());
  Real3View u("test::u", mesh.nCells()), uB("test::uB", mesh.nBoundaryFaces());
  auto hp = Kokkos::create_mirror_view(phi), hpb = Kokkos::create_mirror_view(phiB);
  auto hu = Kokkos::create_mirror_view(u), hub = Kokkos::create_mirror_view(uB);
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> r(-1, 1);
  for (int c = 0; c < mesh.nCells(); ++c) {
    hp(c) = r(gen);
    for (int j = 0; j < 3; ++j) hu(c, j) = r(gen);
  }
  for (int b = 0; b < mesh.nBoundaryFaces(); ++b) {
    hpb(b) = r(gen);
    for (int j = 0; j < 3; ++j) hub(b, j) = r(gen);
  }
  Kokkos::deep_copy(phi, hp);
  Kokkos::deep_copy(phiB, hpb);
  Kokkos::deep_copy(u, hu);
  Kokkos::deep_copy(uB, hub);
  const IndexView bcells = boundaryCells(mesh);
  for (bool subset : {false, true}) {
    const ConstIndexView cells = subset ? ConstIndexView(bcells) : ConstIndexView();
    Real3View g1("test::g1", mesh.nCells()), g2("test::g2", mesh.nCells());
    Tensor3View G1("test::G1", mesh.nCells()), G2("test::G2", mesh.nCells());
    cellGradient(ExecSpace(), GradientScheme::GaussLinear, mesh, geo, fd, phi, phiB, g1, cells);
    cellGradient(ExecSpace(), mesh, st, phi, phiB, g2, cells);
    cellGradient(ExecSpace(), GradientScheme::GaussLinear, mesh, geo, fd, u, uB, G1, cells);
    cellGradient(ExecSpace(), mesh, st, u, uB, G2, cells);
    auto h1 = host(g1), h2 = host(g2);
    auto H1 = host(G1), H2 = host(G2);
    double gmax = 0, diff = 0;
    for (int c = 0; c < mesh.nCells(); ++c)
      for (int i = 0; i < 3; ++i) {
        gmax = std::max(gmax, std::abs(h1(c, i)));
        diff = std::max(diff, std::abs(h1(c, i) - h2(c, i)));
        for (int j = 0; j < 3; ++j) {
          gmax = std::max(gmax, std::abs(H1(c, i, j)));
          diff = std::max(diff, std::abs(H1(c, i, j) - H2(c, i, j)));
        }
      }
    ASSERT_GT(gmax, 1.0) << (subset ? "boundary cells" : "all cells");
    EXPECT_LE(diff, 1e-12 * gmax) << (subset ? "boundary cells" : "all cells");
  }
}

TEST(FvKernels, FaceDataOnAUniformCartesianMesh) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, {4, 4, 4});
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  MeshGeometry geo = allocateGeometry(mesh);
  computeGeometry(ExecSpace(), mesh, geo);
  FvFaceData fd = allocateFaceData(mesh);
  computeFaceData(ExecSpace(), mesh, geo, fd);
  auto w = host(fd.weight), dc = host(fd.deltaCoeff), nd = host(fd.normalDist);
  auto k = host(fd.nonOrth);
  for (int f = 0; f < mesh.nFaces(); ++f) {
    const bool internal = f < mesh.nInternalFaces();
    ASSERT_TRUE(near(w(f), internal ? 0.5 : 1.0, Tol{1e-14, 0}, "weight"));
    // |S|^2 / (S.d) with |S| = 1/16 and d = 1/4 (internal) or 1/8 (boundary).
    ASSERT_TRUE(near(dc(f), internal ? 0.25 : 0.5, Tol{1e-14, 0}, "deltaCoeff"));
    ASSERT_TRUE(near(nd(f), internal ? 0.25 : 0.125, Tol{1e-14, 0}, "normal distance"));
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(near(k(f, i), 0.0, Tol{1e-15, 0}, "non-orthogonal vector"));
  }
}

TEST(FvKernels, SweptVolumesSatisfyTheSpaceConservationLaw) {
  // Random motion of every node (boundary included): for each cell, the signed sum of its faces'
  // swept volumes equals its exact trilinear volume change.
  HexMesh mesh = distortedBox(true);
  MeshGeometry g0 = allocateGeometry(mesh), g1 = allocateGeometry(mesh);
  computeGeometry(ExecSpace(), mesh, g0);
  Real3View oldPts("test::old", mesh.nNodes());
  Kokkos::deep_copy(oldPts, mesh.points());
  auto pts = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.points());
  std::mt19937 gen(21);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n = 0; n < mesh.nNodes(); ++n)
    for (int k = 0; k < 3; ++k) pts(n, k) += 0.04 * u(gen);
  Kokkos::deep_copy(mesh.points(), pts);
  computeGeometry(ExecSpace(), mesh, g1);
  RealView swept("test::swept", mesh.nFaces());
  sweptVolumes(ExecSpace(), mesh, oldPts, mesh.points(), swept);
  RealView dv("test::dv", mesh.nCells());
  divergence<1>(ExecSpace(), mesh, swept, dv, ReductionMode::Gather);
  auto hdv = host(dv), v0 = host(g0.cellVolume), v1 = host(g1.cellVolume);
  double maxChange = 0;
  for (int c = 0; c < mesh.nCells(); ++c) {
    maxChange = std::max(maxChange, std::abs(v1(c) - v0(c)));
    ASSERT_TRUE(near(hdv(c), v1(c) - v0(c), Tol{1e-16, 0}, "cell " + std::to_string(c)));
  }
  EXPECT_GT(maxChange, 1e-4);
  // A pure translation sweeps exactly (area vector . displacement) through each face.
  Kokkos::deep_copy(oldPts, mesh.points());
  for (int n = 0; n < mesh.nNodes(); ++n) {
    pts(n, 0) += 0.01;
    pts(n, 1) -= 0.02;
    pts(n, 2) += 0.005;
  }
  Kokkos::deep_copy(mesh.points(), pts);
  sweptVolumes(ExecSpace(), mesh, oldPts, mesh.points(), swept);
  auto hs = host(swept);
  auto sf = host(g1.faceArea);
  for (int f = 0; f < mesh.nFaces(); ++f)
    ASSERT_TRUE(near(hs(f), 0.01 * sf(f, 0) - 0.02 * sf(f, 1) + 0.005 * sf(f, 2), Tol{1e-16, 1e-12}, "translation"));
}

namespace {
std::set<std::string> gKernelLabels, gAllocLabels;
void onBegin(const char* name, const uint32_t, uint64_t* id) {
  gKernelLabels.insert(name);
  *id = 0;
}
void onAlloc(Kokkos::Profiling::SpaceHandle, const char* label, const void*, uint64_t) { gAllocLabels.insert(label); }
}  // namespace

TEST(FvKernels, EveryKernelAndViewOfTheSolverIsLabelled) {
  auto spec = boxSpec({0, 0, 0}, {1, 1, 0.25}, {4, 4, 1});
  spec.blocks[0].patches = {"in", "out", "wall", "wall", "fb", "fb"};
  spec.patchKinds = {{"wall", PatchKind::Wall}, {"fb", PatchKind::Empty}};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.convection = ConvectionScheme::VanLeer;
  o.reduction = ReductionMode::Scatter;
  o.boundaries["in"].type = BoundaryType::FixedVelocity;
  o.boundaries["in"].velocity = {1, 0, 0};
  o.boundaries["out"].type = BoundaryType::FixedPressure;
  gKernelLabels.clear();
  gAllocLabels.clear();
  Kokkos::Tools::Experimental::set_begin_parallel_for_callback(onBegin);
  Kokkos::Tools::Experimental::set_begin_parallel_reduce_callback(onBegin);
  Kokkos::Tools::Experimental::set_allocate_data_callback(onAlloc);
  {
    FluidSolver fluid(mesh, o);
    fluid.solveStep(0.0, 0.1);
    o.reduction = ReductionMode::Gather;
    FluidSolver fluid2(mesh, o);
    fluid2.solveStep(0.0, 0.1);
  }
  Kokkos::Tools::Experimental::set_begin_parallel_for_callback(nullptr);
  Kokkos::Tools::Experimental::set_begin_parallel_reduce_callback(nullptr);
  Kokkos::Tools::Experimental::set_allocate_data_callback(nullptr);
  if (gKernelLabels.empty()) GTEST_SKIP() << "this Kokkos build does not report kernels to tool callbacks";
  int fluidKernels = 0;
  for (const auto& l : gKernelLabels) {
    if (l.rfind("Kokkos::", 0) == 0) continue;  // Kokkos' own (deep_copy, ScatterView reset)
    // Ours, the geometry's (core) and the linear solvers' (kernels).
    EXPECT_TRUE(l.rfind("mfsi::fluid::", 0) == 0 || l.rfind("mfsi::core::", 0) == 0 ||
                l.rfind("mfsi::kernels::", 0) == 0)
        << "kernel label '" << l << "'";
    fluidKernels += l.rfind("mfsi::fluid::", 0) == 0;
  }
  EXPECT_GT(fluidKernels, 25);
  for (const auto& l : gAllocLabels) {
    if (l.empty() || l.rfind("Kokkos::", 0) == 0) continue;
    // ScatterView names its per-thread copies "duplicated_<label>".
    const std::string base = l.rfind("duplicated_", 0) == 0 ? l.substr(11) : l;
    EXPECT_TRUE(base.rfind("mfsi::", 0) == 0) << "view label '" << l << "'";
  }
}
