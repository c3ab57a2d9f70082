// CSR sparsity builders: adjacency lists, the model Poisson matrix, and cell matrices of hex meshes
// with the face -> coefficient map used by finite-volume assembly.
#include "kernels/CsrBuild.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/MeshGeometry.hpp"
#include "support/Approx.hpp"
#include "support/FvLaplacian.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::near;
using mfsi::test::Tol;

template <class View>
std::vector<typename View::non_const_value_type> host(const View& v) {
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), v);
  return std::vector<typename View::non_const_value_type>(h.data(), h.data() + h.extent(0));
}

/// Rows sorted and unique, diagIdx pointing at the diagonal.
void expectWellFormed(const mfsi::CsrMatrix& A) {
  const auto rp = host(A.rowPtr), ci = host(A.colIdx), di = host(A.diagIdx);
  ASSERT_EQ(rp.size(), static_cast<std::size_t>(A.nRows + 1));
  EXPECT_EQ(rp.back(), A.nnz());
  for (lid_t i = 0; i < A.nRows; ++i) {
    for (lid_t k = rp[i] + 1; k < rp[i + 1]; ++k) ASSERT_LT(ci[k - 1], ci[k]) << "row " << i;
    if (di[i] >= 0) {
      EXPECT_EQ(ci[di[i]], i) << "row " << i;
    } else {
      EXPECT_TRUE(std::find(ci.begin() + rp[i], ci.begin() + rp[i + 1], i) == ci.begin() + rp[i + 1]) << i;
    }
  }
}

}  // namespace

TEST(CsrBuild, AdjacencyListIsSortedDeduplicatedWithDiagonal) {
  const std::vector<std::vector<lid_t>> adj = {{3, 1, 1}, {}, {0}, {2, 0}};
  const auto A = mfsi::buildCsr(adj);
  EXPECT_EQ(A.nRows, 4);
  EXPECT_EQ(A.nCols, 4);
  expectWellFormed(A);
  EXPECT_EQ(host(A.rowPtr), (std::vector<lid_t>{0, 3, 4, 6, 9}));
  EXPECT_EQ(host(A.colIdx), (std::vector<lid_t>{0, 1, 3, 1, 0, 2, 0, 2, 3}));
  EXPECT_EQ(host(A.diagIdx), (std::vector<lid_t>{0, 3, 5, 8}));

  mfsi::CsrBuildOptions noDiag;
  noDiag.addDiagonal = false;
  const auto B = mfsi::buildCsr(adj, noDiag);
  expectWellFormed(B);
  EXPECT_EQ(B.nnz(), 5);
  EXPECT_EQ(host(B.diagIdx)[1], -1);
}

TEST(CsrBuild, OffsetsFormBlocksAndGhostColumns) {
  // Two nodes coupled to each other, as 3x3 blocks: every row holds 6 columns.
  mfsi::CsrBuildOptions opt;
  opt.blockSize = 3;
  const auto A = mfsi::buildCsr(std::vector<lid_t>{0, 1, 2}, std::vector<lid_t>{1, 0}, opt);
  EXPECT_EQ(A.nRows, 6);
  EXPECT_EQ(A.nnz(), 36);
  expectWellFormed(A);
  const auto ci = host(A.colIdx);
  EXPECT_EQ(std::vector<lid_t>(ci.begin() + 24, ci.begin() + 30), (std::vector<lid_t>{0, 1, 2, 3, 4, 5}));

  mfsi::CsrBuildOptions ghosts;
  ghosts.nCols = 5;
  const auto G = mfsi::buildCsr(std::vector<std::vector<lid_t>>{{4}, {3}}, ghosts);
  EXPECT_EQ(G.nCols, 5);
  EXPECT_EQ(host(G.colIdx), (std::vector<lid_t>{0, 4, 1, 3}));
}

TEST(CsrBuild, RejectsOutOfRangeColumnsAndBadOffsets) {
  EXPECT_THROW(mfsi::buildCsr(std::vector<std::vector<lid_t>>{{0}, {2}}), mfsi::InputError);
  EXPECT_THROW(mfsi::buildCsr(std::vector<std::vector<lid_t>>{{-1}}), mfsi::InputError);
  EXPECT_THROW(mfsi::buildCsr(std::vector<lid_t>{0, 2, 1}, std::vector<lid_t>{0}), mfsi::InputError);
}

TEST(CsrBuild, Poisson7RowSumsFollowTheBoundaryConditions) {
  const std::array<lid_t, 3> n{4, 3, 5};
  const auto D = mfsi::buildPoisson7(n, mfsi::ModelBoundary::Dirichlet);
  const auto N = mfsi::buildPoisson7(n, mfsi::ModelBoundary::Neumann);
  expectWellFormed(D);
  EXPECT_EQ(D.nRows, 60);
  // 7-point: nnz = cells + 2 x internal faces.
  const lid_t internalFaces = 3 * 3 * 5 + 4 * 2 * 5 + 4 * 3 * 4;
  EXPECT_EQ(D.nnz(), 60 + 2 * internalFaces);
  const auto rp = host(D.rowPtr), ci = host(D.colIdx);
  const auto dv = host(D.values), nv = host(N.values);
  for (lid_t k = 0; k < n[2]; ++k)
    for (lid_t j = 0; j < n[1]; ++j)
      for (lid_t i = 0; i < n[0]; ++i) {
        const lid_t c = i + n[0] * (j + n[1] * k);
        const int boundaryFaces = (i == 0) + (i == n[0] - 1) + (j == 0) + (j == n[1] - 1) + (k == 0) + (k == n[2] - 1);
        double sd = 0, sn = 0;
        for (lid_t e = rp[c]; e < rp[c + 1]; ++e) {
          sd += dv[e];
          sn += nv[e];
          if (ci[e] != c) {
            // Symmetric: a_cj = a_jc.
            const lid_t j2 = ci[e];
            const lid_t back = mfsi::findEntry(rp, ci, j2, c);
            ASSERT_GE(back, 0);
            EXPECT_EQ(dv[back], dv[e]);
          }
        }
        EXPECT_EQ(sn, 0.0) << "Neumann row " << c;
        EXPECT_EQ(sd, 2.0 * boundaryFaces) << "Dirichlet row " << c;
      }
}

TEST(CsrBuild, CellMatrixOfABoxAndItsFaceMap) {
  const auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(mfsi::boxSpec({0, 0, 0}, {3, 2, 4}, {3, 2, 4})));
  const auto cc = mfsi::buildCellCsr(mesh);
  const auto& A = cc.matrix;
  EXPECT_EQ(A.nRows, mesh.nCells());
  EXPECT_EQ(A.nnz(), mesh.nCells() + 2 * mesh.nInternalFaces());
  expectWellFormed(A);
  const auto rp = host(A.rowPtr), ci = host(A.colIdx), di = host(A.diagIdx);
  const auto own = host(mesh.faceOwner()), nb = host(mesh.faceNeighbour());
  const auto pn = host(cc.faceMap.ownerRow), np = host(cc.faceMap.neighbourRow);
  ASSERT_EQ(pn.size(), static_cast<std::size_t>(mesh.nInternalFaces()));
  std::vector<int> seen(A.nnz(), 0);
  for (lid_t f = 0; f < mesh.nInternalFaces(); ++f) {
    // a_PN sits in row P at column N, a_NP in row N at column P.
    ASSERT_GE(pn[f], rp[own[f]]);
    ASSERT_LT(pn[f], rp[own[f] + 1]);
    EXPECT_EQ(ci[pn[f]], nb[f]);
    ASSERT_GE(np[f], rp[nb[f]]);
    ASSERT_LT(np[f], rp[nb[f] + 1]);
    EXPECT_EQ(ci[np[f]], own[f]);
    ++seen[pn[f]];
    ++seen[np[f]];
  }
  for (lid_t i = 0; i < A.nRows; ++i) ++seen[di[i]];
  for (lid_t k = 0; k < A.nnz(); ++k) EXPECT_EQ(seen[k], 1) << "entry " << k << " claimed once";
}

TEST(CsrBuild, FaceMapAssemblesTheFiniteVolumeLaplacian) {
  // How the fluid assembles: one thread per cell walks its faces and writes only its own row
  // (deterministic, no atomics): a_PN = -|S|/|d|, a_PP = sum of the face coefficients (Neumann).
  const auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {4, 4, 4})));
  auto geo = mfsi::allocateGeometry(mesh);
  mfsi::ExecSpace exec;
  mfsi::computeGeometry(exec, mesh, geo);
  const auto cc = mfsi::buildCellCsr(mesh);
  mfsi::test::assembleFvLaplacian(exec, mesh, geo, cc);
  // On the uniform 4^3 cube mesh of h = 1/4: coefficients h^2 / h = 1/4, so 4 A is the Neumann
  // model matrix up to the cell numbering; compare the sorted row patterns and the values.
  const auto model = mfsi::buildPoisson7({4, 4, 4}, mfsi::ModelBoundary::Neumann);
  const auto av = host(cc.matrix.values), mv = host(model.values);
  const auto arp = host(cc.matrix.rowPtr), mrp = host(model.rowPtr);
  std::vector<std::vector<double>> rowsA, rowsM;
  for (lid_t i = 0; i < 64; ++i) {
    rowsA.emplace_back(av.begin() + arp[i], av.begin() + arp[i + 1]);
    rowsM.emplace_back(mv.begin() + mrp[i], mv.begin() + mrp[i + 1]);
    double s = 0;
    for (double v : rowsA.back()) s += v;
    EXPECT_TRUE(near(s, 0.0, Tol{1e-12, 0}, "row sum " + std::to_string(i)));
    // Round away the last bits so that sorting the rows below cannot depend on rounding.
    for (auto& v : rowsA.back()) v = std::round(v * 4.0 * 1e9) * 1e-9;
    std::sort(rowsA.back().begin(), rowsA.back().end());
    std::sort(rowsM.back().begin(), rowsM.back().end());
  }
  for (auto* rows : {&rowsA, &rowsM}) std::sort(rows->begin(), rows->end());
  ASSERT_EQ(rowsA.size(), rowsM.size());
  for (std::size_t i = 0; i < rowsA.size(); ++i) {
    ASSERT_EQ(rowsA[i].size(), rowsM[i].size());
    for (std::size_t k = 0; k < rowsA[i].size(); ++k)
      EXPECT_TRUE(near(rowsA[i][k], rowsM[i][k], Tol{1e-12, 1e-12}, "row value"));
  }
}
