#include "kernels/Amg.hpp"

#include "core/Error.hpp"
#include "kernels/CsrBuild.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace mfsi {

namespace {

using DenseView = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>;
using HostUnmanagedIdx = Kokkos::View<const lid_t*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>;

/// Eigenvalues of the coarsest operator below this fraction of the largest are treated as zero
/// (null space of a singular system) by the pseudo-inverse.
constexpr double kPseudoInverseTol = 1e-10;
/// Relative coupling |a_ij| / sqrt(a_ii a_jj) below which an entry counts as zero in aggregation.
constexpr double kNegligible = 1e-10;
/// Smoother sweeps on a coarsest level too large for the dense solve (coarsening stalled).
constexpr int kCoarseSweeps = 10;
/// Chebyshev's upper bound is the Lanczos estimate (never above the true value) times this.
constexpr double kChebyshevBoost = 1.1;

// ---------------------------------------------------------------------------------------------
// Host-side set-up helpers (sparsity only; values are computed by the device kernels below).
// ---------------------------------------------------------------------------------------------

struct HostCsr {
  lid_t nRows = 0;
  std::vector<lid_t> rowPtr, colIdx, diagIdx;
  std::vector<double> values;
};

template <class View>
std::vector<typename View::non_const_value_type> hostCopy(const View& v) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return std::vector<typename View::non_const_value_type>(h.data(), h.data() + h.extent(0));
}

HostCsr hostCopy(const CsrMatrix& A) {
  HostCsr h;
  h.nRows = A.nRows;
  h.rowPtr = hostCopy(A.rowPtr);
  h.colIdx = hostCopy(A.colIdx);
  h.diagIdx = hostCopy(A.diagIdx);
  h.values = hostCopy(A.values);
  return h;
}

IndexView upload(const std::vector<lid_t>& v, const std::string& label) {
  IndexView d(Kokkos::view_alloc(Kokkos::WithoutInitializing, label), v.size());
  Kokkos::deep_copy(d, HostUnmanagedIdx(v.data(), v.size()));
  return d;
}

/// Device CSR with the given sparsity and zero values.
CsrMatrix makeCsr(lid_t nRows, lid_t nCols, const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx,
                  const std::string& label) {
  CsrMatrix M;
  M.nRows = nRows;
  M.nCols = nCols;
  M.rowPtr = upload(rowPtr, label + "::rowPtr");
  M.colIdx = upload(colIdx, label + "::colIdx");
  std::vector<lid_t> diag(nRows, -1);
  if (nRows == nCols)
    for (lid_t i = 0; i < nRows; ++i) diag[i] = findEntry(rowPtr, colIdx, i, i);
  M.diagIdx = upload(diag, label + "::diagIdx");
  M.values = RealView(label + "::values", colIdx.size());
  return M;
}

/// Greedy three-phase aggregation on the strength graph (Vanek et al. 1996; as in ML/MueLu's
/// "uncoupled" aggregation). Returns the aggregate of every row, -1 for rows without any
/// off-diagonal coupling (they need no coarse correction: the smoother solves them exactly).
std::vector<lid_t> aggregate(const HostCsr& A, double theta, lid_t& nAgg) {
  const lid_t n = A.nRows;
  // Strong neighbours of each row, with the coupling magnitude.
  std::vector<lid_t> sPtr(n + 1, 0), sIdx;
  std::vector<double> sVal;
  std::vector<char> coupled(n, 0);
  for (lid_t i = 0; i < n; ++i) {
    const double di = std::abs(A.values[A.diagIdx[i]]);
    for (lid_t k = A.rowPtr[i]; k < A.rowPtr[i + 1]; ++k) {
      const lid_t j = A.colIdx[k];
      const double a = std::abs(A.values[k]);
      const double dj = std::abs(A.values[A.diagIdx[j]]);
      // Couplings below kNegligible relative size are rounding left-overs of cancellation in
      // the Galerkin product: treating them as couplings would make aggregates depend on
      // rounding (and a value update on the same sparsity would not reproduce a fresh set-up).
      if (j == i || a * a <= kNegligible * kNegligible * di * dj) continue;
      coupled[i] = 1;
      if (a * a >= theta * theta * di * dj) {
        sIdx.push_back(j);
        sVal.push_back(a);
      }
    }
    sPtr[i + 1] = static_cast<lid_t>(sIdx.size());
  }

  constexpr lid_t kFree = -2;
  std::vector<lid_t> agg(n, kFree);
  nAgg = 0;
  // Phase 1: a free row whose strong neighbours are all free becomes a root and takes them all.
  // Aggregates are disjoint "stars" of diameter 2: ~7 rows on a 7-point stencil.
  for (lid_t i = 0; i < n; ++i) {
    if (agg[i] != kFree || sPtr[i] == sPtr[i + 1]) continue;
    bool allFree = true;
    for (lid_t k = sPtr[i]; k < sPtr[i + 1] && allFree; ++k) allFree = agg[sIdx[k]] == kFree;
    if (!allFree) continue;
    agg[i] = nAgg;
    for (lid_t k = sPtr[i]; k < sPtr[i + 1]; ++k) agg[sIdx[k]] = nAgg;
    ++nAgg;
  }
  // Phase 2: a leftover row joins the phase-1 aggregate it is most strongly coupled to (phase-1
  // snapshot, so aggregates grow by one layer at most and stay compact).
  const std::vector<lid_t> phase1 = agg;
  for (lid_t i = 0; i < n; ++i) {
    if (agg[i] != kFree) continue;
    double best = 0.0;
    for (lid_t k = sPtr[i]; k < sPtr[i + 1]; ++k)
      if (phase1[sIdx[k]] >= 0 && sVal[k] > best) {
        best = sVal[k];
        agg[i] = phase1[sIdx[k]];
      }
  }
  // Phase 3: what is left forms new aggregates with its free strong neighbours, or joins the
  // strongest aggregated neighbour; rows without strong couplings become singletons.
  for (lid_t i = 0; i < n; ++i) {
    if (agg[i] != kFree) continue;
    if (!coupled[i]) {
      agg[i] = -1;
      continue;
    }
    bool anyFree = false;
    for (lid_t k = sPtr[i]; k < sPtr[i + 1]; ++k) anyFree = anyFree || agg[sIdx[k]] == kFree;
    if (!anyFree && sPtr[i] < sPtr[i + 1]) {
      double best = 0.0;
      for (lid_t k = sPtr[i]; k < sPtr[i + 1]; ++k)
        if (agg[sIdx[k]] >= 0 && sVal[k] > best) {
          best = sVal[k];
          agg[i] = agg[sIdx[k]];
        }
      continue;
    }
    agg[i] = nAgg;
    for (lid_t k = sPtr[i]; k < sPtr[i + 1]; ++k)
      if (agg[sIdx[k]] == kFree) agg[sIdx[k]] = nAgg;
    ++nAgg;
  }
  return agg;
}

/// Transpose of a sparsity (columns come out sorted); map(t) = position in the original of
/// transposed entry t.
void transpose(lid_t nRows, lid_t nCols, const std::vector<lid_t>& ptr, const std::vector<lid_t>& idx,
               std::vector<lid_t>& tPtr, std::vector<lid_t>& tIdx, std::vector<lid_t>& map) {
  tPtr.assign(nCols + 1, 0);
  for (lid_t c : idx) ++tPtr[c + 1];
  for (lid_t c = 0; c < nCols; ++c) tPtr[c + 1] += tPtr[c];
  std::vector<lid_t> fill(tPtr.begin(), tPtr.end() - 1);
  tIdx.resize(idx.size());
  map.resize(idx.size());
  for (lid_t i = 0; i < nRows; ++i)
    for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) {
      const lid_t t = fill[idx[k]]++;
      tIdx[t] = i;
      map[t] = k;
    }
}

/// Sparsity of the product C = A B (A: nRows rows, B: nColsB columns), row by row with a marker
/// array. The Galerkin operator is built as two such products, A P then R (A P): cheaper than the
/// triple product R A P row by row (which repeats the work of A P for every coarse row touching a
/// fine row: 4x more work on the second level of a 3D hierarchy).
void productSparsity(lid_t nRows, const std::vector<lid_t>& aPtr, const std::vector<lid_t>& aIdx,
                     const std::vector<lid_t>& bPtr, const std::vector<lid_t>& bIdx, lid_t nColsB,
                     std::vector<lid_t>& cPtr, std::vector<lid_t>& cIdx) {
  std::vector<lid_t> mark(nColsB, -1), row;
  cPtr.assign(nRows + 1, 0);
  cIdx.clear();
  for (lid_t i = 0; i < nRows; ++i) {
    row.clear();
    for (lid_t ka = aPtr[i]; ka < aPtr[i + 1]; ++ka) {
      const lid_t k = aIdx[ka];
      for (lid_t kb = bPtr[k]; kb < bPtr[k + 1]; ++kb) {
        const lid_t j = bIdx[kb];
        if (mark[j] != i) {
          mark[j] = i;
          row.push_back(j);
        }
      }
    }
    std::sort(row.begin(), row.end());
    cIdx.insert(cIdx.end(), row.begin(), row.end());
    cPtr[i + 1] = static_cast<lid_t>(cIdx.size());
  }
}

// ---------------------------------------------------------------------------------------------
// Device kernels. Each writes only its own row: deterministic, no atomics.
// ---------------------------------------------------------------------------------------------

/// Position of column c in the sorted range [lo, hi) of idx (c must be present).
KOKKOS_INLINE_FUNCTION lid_t findSorted(const ConstIndexView& idx, lid_t lo, lid_t hi, lid_t c) {
  while (lo < hi) {
    const lid_t mid = lo + (hi - lo) / 2;
    if (idx(mid) < c)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/// P = (I - omega D^{-1} A) P_tent with P_tent(i, agg(i)) = 1, into P's fixed sparsity.
void smoothedProlongatorValues(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& invDiag,
                               const ConstIndexView& agg, double omega, const CsrMatrix& P) {
  const ConstIndexView aPtr = A.rowPtr, aCol = A.colIdx, pPtr = P.rowPtr, pCol = P.colIdx;
  const ConstRealView aVal = A.values;
  const RealView pVal = P.values;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::prolongator", RangePolicy(exec, 0, A.nRows), KOKKOS_LAMBDA(lid_t i) {
        const lid_t p0 = pPtr(i), p1 = pPtr(i + 1);
        for (lid_t kp = p0; kp < p1; ++kp) pVal(kp) = 0.0;
        const double w = omega * invDiag(i);
        for (lid_t ka = aPtr(i); ka < aPtr(i + 1); ++ka) {
          const lid_t J = agg(aCol(ka));
          if (J >= 0) pVal(findSorted(pCol, p0, p1, J)) -= w * aVal(ka);
        }
        if (agg(i) >= 0) pVal(findSorted(pCol, p0, p1, agg(i))) += 1.0;
      });
}

/// R = P^T values through the transpose map.
void transposeValues(const ExecSpace& exec, const ConstIndexView& map, const ConstRealView& pVal,
                     const RealView& rVal) {
  Kokkos::parallel_for(
      "mfsi::kernels::amg::restrictionValues", RangePolicy(exec, 0, static_cast<lid_t>(map.extent(0))),
      KOKKOS_LAMBDA(lid_t t) { rVal(t) = pVal(map(t)); });
}

/// C = A B into C's fixed sparsity (which contains the product's pattern). One thread per row of
/// C; each product lands by binary search in the (short, sorted) row.
void productValues(const ExecSpace& exec, const CsrMatrix& A, const CsrMatrix& B, const CsrMatrix& C) {
  const ConstIndexView aPtr = A.rowPtr, aCol = A.colIdx, bPtr = B.rowPtr, bCol = B.colIdx, cPtr = C.rowPtr,
                       cCol = C.colIdx;
  const ConstRealView aVal = A.values, bVal = B.values;
  const RealView cVal = C.values;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::product", RangePolicy(exec, 0, C.nRows), KOKKOS_LAMBDA(lid_t i) {
        const lid_t c0 = cPtr(i), c1 = cPtr(i + 1);
        for (lid_t kc = c0; kc < c1; ++kc) cVal(kc) = 0.0;
        for (lid_t ka = aPtr(i); ka < aPtr(i + 1); ++ka) {
          const lid_t k = aCol(ka);
          const double a = aVal(ka);
          for (lid_t kb = bPtr(k); kb < bPtr(k + 1); ++kb) cVal(findSorted(cCol, c0, c1, bCol(kb))) += a * bVal(kb);
        }
      });
}

/// Largest eigenvalue of D^{-1} A, estimated by `steps` Lanczos steps on the similar symmetric
/// matrix M = |D|^{-1/2} A |D|^{-1/2} (largest |Ritz value| of the tridiagonal Lanczos matrix).
/// Why Lanczos and not the power method: for Laplacians the top of the spectrum is dense, and
/// ten power steps underestimate lambda_max by 10-20 %, which makes the Chebyshev smoother
/// amplify the top modes; ten Lanczos steps are within a few percent (Ritz values never exceed
/// lambda_max, so a small boost factor is still applied). Starts from a fixed pseudo-random
/// vector (not the constant, the null vector of a Neumann problem). Set-up only.
double estimateLambdaMax(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& invDiag, int steps) {
  const lid_t n = A.nRows;
  const std::string pre = "mfsi::kernels::amg::lanczos";
  RealView vPrev(pre + "::vPrev", n), v(Kokkos::view_alloc(Kokkos::WithoutInitializing, pre + "::v"), n),
      w(Kokkos::view_alloc(Kokkos::WithoutInitializing, pre + "::w"), n),
      s(Kokkos::view_alloc(Kokkos::WithoutInitializing, pre + "::s"), n);
  Kokkos::parallel_for(
      "mfsi::kernels::amg::lanczosStart", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        const unsigned h = static_cast<unsigned>(i) * 2654435761u + 12345u;
        v(i) = static_cast<double>((h >> 8) & 0xffff) / 65535.0 - 0.5;
        s(i) = kmath::sqrt(kmath::fabs(invDiag(i)));
      });
  const SolverComm comm;
  double beta = blas::norm2(exec, comm, n, v);
  blas::axpby(exec, n, 1.0 / beta, v, 0.0, v);
  beta = 0.0;
  const ConstIndexView aPtr = A.rowPtr, aCol = A.colIdx;
  const ConstRealView aVal = A.values;
  std::vector<double> alphas, betas;
  for (int j = 0; j < steps; ++j) {
    // w = M v - beta vPrev, alpha = w.v
    const double b0 = beta;
    const double alpha = blas::reduce<1>(
        exec, comm, "mfsi::kernels::amg::lanczosApply", n, KOKKOS_LAMBDA(lid_t i, blas::Sums<1> & acc) {
          double mv = 0.0;
          for (lid_t k = aPtr(i); k < aPtr(i + 1); ++k) mv += aVal(k) * s(aCol(k)) * v(aCol(k));
          const double wi = s(i) * mv - b0 * vPrev(i);
          w(i) = wi;
          acc[0] += wi * v(i);
        })[0];
    alphas.push_back(alpha);
    // w -= alpha v; beta = ||w||
    const double ww = blas::reduce<1>(
        exec, comm, "mfsi::kernels::amg::lanczosOrthogonalise", n, KOKKOS_LAMBDA(lid_t i, blas::Sums<1> & acc) {
          const double wi = w(i) - alpha * v(i);
          w(i) = wi;
          acc[0] += wi * wi;
        })[0];
    beta = std::sqrt(ww);
    if (!(beta > 1e-14 * std::abs(alpha))) break;  // invariant subspace found (or NaN)
    betas.push_back(beta);
    const double inv = 1.0 / beta;
    Kokkos::parallel_for(
        "mfsi::kernels::amg::lanczosNext", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
          vPrev(i) = v(i);
          v(i) = inv * w(i);
        });
  }
  const int k = static_cast<int>(alphas.size());
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
  for (int i = 0; i < k; ++i) {
    T(i, i) = alphas[i];
    if (i + 1 < k) T(i, i + 1) = T(i + 1, i) = betas[i];
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues().cwiseAbs().maxCoeff();
}

/// d = c1 d + c2 D^{-1} (b - A x) (c1 == 0: d is not read); then x += d.
void smootherStep(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& invDiag, const ConstRealView& b,
                  const RealView& x, const RealView& d, double c1, double c2) {
  const ConstIndexView aPtr = A.rowPtr, aCol = A.colIdx;
  const ConstRealView aVal = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::smoother", RangePolicy(exec, 0, A.nRows), KOKKOS_LAMBDA(lid_t i) {
        double ri = b(i);
        for (lid_t k = aPtr(i); k < aPtr(i + 1); ++k) ri -= aVal(k) * x(aCol(k));
        const double di = c2 * invDiag(i) * ri;
        d(i) = c1 == 0.0 ? di : c1 * d(i) + di;
      });
  blas::axpy(exec, A.nRows, 1.0, d, x);
}

/// First step from a zero initial guess: x = d = c2 D^{-1} b (no SpMV).
void smootherFirstStep(const ExecSpace& exec, lid_t n, const ConstRealView& invDiag, const ConstRealView& b,
                       const RealView& x, const RealView& d, double c2) {
  Kokkos::parallel_for(
      "mfsi::kernels::amg::smootherFirst", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        const double di = c2 * invDiag(i) * b(i);
        d(i) = di;
        x(i) = di;
      });
}

/// r = b - A x.
void residualOnly(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& x, const ConstRealView& b,
                  const RealView& r) {
  const ConstIndexView aPtr = A.rowPtr, aCol = A.colIdx;
  const ConstRealView aVal = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::residual", RangePolicy(exec, 0, A.nRows), KOKKOS_LAMBDA(lid_t i) {
        double ri = b(i);
        for (lid_t k = aPtr(i); k < aPtr(i + 1); ++k) ri -= aVal(k) * x(aCol(k));
        r(i) = ri;
      });
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The hierarchy.
// ---------------------------------------------------------------------------------------------

struct detail::AmgHierarchy {
  struct Level {
    CsrMatrix A;   ///< this level's operator (level 0: the caller's matrix, shallow)
    CsrMatrix P;   ///< prolongation from the next level (absent on the coarsest)
    CsrMatrix R;   ///< P^T
    CsrMatrix AP;  ///< A P, kept for the value updates of the Galerkin product R (A P)
    IndexView rToP;
    IndexView agg;
    RealView invDiag;
    double lambdaMax = 0.0;
    RealView x, b, r, d;  ///< work vectors (level 0 uses the apply arguments as x and b)
  };
  std::vector<Level> levels;
  DenseView coarseInverse;
  bool direct = false;
};

AmgPreconditioner::AmgPreconditioner(const AmgOptions& options) : options_(options) {
  MFSI_CHECK(options.sweeps >= 1, "amg: sweeps must be >= 1");
  MFSI_CHECK(options.chebyshevDegree >= 1, "amg: chebyshevDegree must be >= 1");
  MFSI_CHECK(options.chebyshevRatio > 1.0, "amg: chebyshevRatio must be > 1");
  MFSI_CHECK(options.strengthThreshold >= 0.0 && options.strengthThreshold < 1.0,
             "amg: strengthThreshold must be in [0, 1)");
  MFSI_CHECK(options.coarseSize >= 1 && options.maxLevels >= 1, "amg: coarseSize and maxLevels must be >= 1");
  MFSI_CHECK(options.eigenSteps >= 1, "amg: eigenSteps must be >= 1");
}

AmgPreconditioner::~AmgPreconditioner() = default;

namespace {

using Level = detail::AmgHierarchy::Level;

/// Diagonal inverse and lambda_max(D^{-1} A) of a level (values only).
void levelSmootherData(const ExecSpace& exec, Level& L, int eigenSteps) {
  invertDiagonal(exec, L.A, L.invDiag);
  L.lambdaMax = estimateLambdaMax(exec, L.A, L.invDiag, eigenSteps);
  MFSI_CHECK(L.lambdaMax > 0.0 && std::isfinite(L.lambdaMax),
             "amg: could not estimate the spectral radius (rows " << L.A.nRows << ", estimate " << L.lambdaMax << ")");
}

/// Values of P, R and the next coarse operator from level `fine`'s values.
void levelTransferValues(const ExecSpace& exec, Level& fine, Level& coarse, const AmgOptions& opt) {
  if (opt.prolongation == AmgProlongation::Smoothed) {
    smoothedProlongatorValues(exec, fine.A, fine.invDiag, fine.agg, opt.prolongatorDamping / fine.lambdaMax, fine.P);
  } else {
    Kokkos::deep_copy(exec, fine.P.values, 1.0);
  }
  transposeValues(exec, fine.rToP, fine.P.values, fine.R.values);
  productValues(exec, fine.A, fine.P, fine.AP);
  productValues(exec, fine.R, fine.AP, coarse.A);
}

/// Dense (pseudo-)inverse of the coarsest operator, on the host with Eigen.
void coarsestInverse(const ExecSpace& exec, detail::AmgHierarchy& h, lid_t maxDirect) {
  const Level& L = h.levels.back();
  const lid_t n = L.A.nRows;
  h.direct = n <= maxDirect;
  if (!h.direct) return;
  exec.fence();
  const HostCsr a = hostCopy(L.A);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (lid_t i = 0; i < n; ++i)
    for (lid_t k = a.rowPtr[i]; k < a.rowPtr[i + 1]; ++k) dense(i, a.colIdx[k]) = a.values[k];
  const double scale = dense.cwiseAbs().maxCoeff();
  const bool symmetric = (dense - dense.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale;
  Eigen::MatrixXd inv;
  if (symmetric) {
    // Pseudo-inverse by eigen-decomposition: drops the null space of a singular (Neumann) system.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(dense);
    const Eigen::VectorXd lam = es.eigenvalues();
    const double cut = kPseudoInverseTol * lam.cwiseAbs().maxCoeff();
    Eigen::VectorXd inverted(n);
    for (lid_t i = 0; i < n; ++i) inverted(i) = std::abs(lam(i)) > cut ? 1.0 / lam(i) : 0.0;
    inv = es.eigenvectors() * inverted.asDiagonal() * es.eigenvectors().transpose();
  } else {
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(dense);
    cod.setThreshold(kPseudoInverseTol);
    inv = cod.pseudoInverse();
  }
  h.coarseInverse =
      DenseView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::kernels::amg::coarseInverse"), n, n);
  auto host = Kokkos::create_mirror_view(h.coarseInverse);
  for (lid_t i = 0; i < n; ++i)
    for (lid_t j = 0; j < n; ++j) host(i, j) = inv(i, j);
  Kokkos::deep_copy(h.coarseInverse, host);
}

void allocateLevelVectors(Level& L, std::size_t l) {
  const lid_t n = L.A.nRows;
  const std::string pre = "mfsi::kernels::amg::level" + std::to_string(l) + "::";
  L.invDiag = RealView(pre + "invDiag", n);
  L.r = RealView(pre + "r", n);
  L.d = RealView(pre + "d", n);
  if (l > 0) {
    L.x = RealView(pre + "x", n);
    L.b = RealView(pre + "b", n);
  }
}

bool sameSparsity(const ExecSpace& exec, const CsrMatrix& a, const CsrMatrix& b) {
  if (a.nRows != b.nRows || a.nCols != b.nCols || a.nnz() != b.nnz()) return false;
  if (a.rowPtr.data() == b.rowPtr.data() && a.colIdx.data() == b.colIdx.data()) return true;
  const ConstIndexView ap = a.rowPtr, bp = b.rowPtr, ac = a.colIdx, bc = b.colIdx;
  lid_t diff = 0;
  Kokkos::parallel_reduce(
      "mfsi::kernels::amg::compareSparsity", RangePolicy(exec, 0, a.nRows),
      KOKKOS_LAMBDA(lid_t i, lid_t & acc) {
        if (ap(i + 1) != bp(i + 1)) {
          ++acc;
          return;
        }
        for (lid_t k = ap(i); k < ap(i + 1); ++k) acc += ac(k) != bc(k) ? 1 : 0;
      },
      diff);
  return diff == 0;
}

}  // namespace

void AmgPreconditioner::setup(const ExecSpace& exec, const CsrMatrix& A) {
  ScopedRegion region("mfsi::kernels::amg::setup");
  MFSI_CHECK(A.nRows == A.nCols,
             "amg: square matrices on one rank only (nRows " << A.nRows << ", nCols " << A.nCols << ")");
  MFSI_CHECK(A.nRows > 0, "amg: empty matrix");
  h_ = std::make_unique<detail::AmgHierarchy>();
  auto& lv = h_->levels;
  lv.emplace_back();
  lv[0].A = A;
  for (std::size_t l = 0;; ++l) {
    allocateLevelVectors(lv[l], l);
    levelSmootherData(exec, lv[l], options_.eigenSteps);
    const lid_t n = lv[l].A.nRows;
    if (n <= options_.coarseSize || static_cast<int>(l) + 1 >= options_.maxLevels) break;

    exec.fence();
    const HostCsr a = hostCopy(lv[l].A);
    lid_t nc = 0;
    const std::vector<lid_t> agg = aggregate(a, l == 0 ? options_.strengthThreshold : 0.0, nc);
    // Stop when coarsening stalls (e.g. no couplings left): the coarsest level takes over.
    if (nc == 0 || nc > n - n / 8) break;

    // Prolongator sparsity: smoothed P couples row i with the aggregates of its matrix neighbours.
    std::vector<lid_t> pPtr(n + 1, 0), pIdx, row;
    for (lid_t i = 0; i < n; ++i) {
      row.clear();
      if (options_.prolongation == AmgProlongation::Smoothed) {
        for (lid_t k = a.rowPtr[i]; k < a.rowPtr[i + 1]; ++k)
          if (agg[a.colIdx[k]] >= 0) row.push_back(agg[a.colIdx[k]]);
        std::sort(row.begin(), row.end());
        row.erase(std::unique(row.begin(), row.end()), row.end());
      } else if (agg[i] >= 0) {
        row.push_back(agg[i]);
      }
      pIdx.insert(pIdx.end(), row.begin(), row.end());
      pPtr[i + 1] = static_cast<lid_t>(pIdx.size());
    }
    std::vector<lid_t> rPtr, rIdx, rToP, apPtr, apIdx, cPtr, cIdx;
    transpose(n, nc, pPtr, pIdx, rPtr, rIdx, rToP);
    productSparsity(n, a.rowPtr, a.colIdx, pPtr, pIdx, nc, apPtr, apIdx);
    productSparsity(nc, rPtr, rIdx, apPtr, apIdx, nc, cPtr, cIdx);

    const std::string pre = "mfsi::kernels::amg::level" + std::to_string(l);
    lv[l].agg = upload(agg, pre + "::aggregate");
    lv[l].P = makeCsr(n, nc, pPtr, pIdx, pre + "::P");
    lv[l].R = makeCsr(nc, n, rPtr, rIdx, pre + "::R");
    lv[l].rToP = upload(rToP, pre + "::rToP");
    lv[l].AP = makeCsr(n, nc, apPtr, apIdx, pre + "::AP");
    Level next;
    next.A = makeCsr(nc, nc, cPtr, cIdx, "mfsi::kernels::amg::level" + std::to_string(l + 1) + "::A");
    lv.push_back(next);
    levelTransferValues(exec, lv[l], lv[l + 1], options_);
  }
  coarsestInverse(exec, *h_, options_.maxDirectSize);
}

void AmgPreconditioner::updateValues(const ExecSpace& exec, const CsrMatrix& A) {
  if (!h_ || !sameSparsity(exec, h_->levels[0].A, A)) return setup(exec, A);
  ScopedRegion region("mfsi::kernels::amg::updateValues");
  auto& lv = h_->levels;
  lv[0].A = A;
  for (std::size_t l = 0; l < lv.size(); ++l) {
    levelSmootherData(exec, lv[l], options_.eigenSteps);
    if (l + 1 < lv.size()) levelTransferValues(exec, lv[l], lv[l + 1], options_);
  }
  coarsestInverse(exec, *h_, options_.maxDirectSize);
}

void AmgPreconditioner::updateFinestSmoother(const ExecSpace& exec, const CsrMatrix& A) {
  MFSI_CHECK(h_ && sameSparsity(exec, h_->levels[0].A, A),
             "amg: updateFinestSmoother() needs a set-up on the same sparsity");
  ScopedRegion region("mfsi::kernels::amg::updateFinestSmoother");
  h_->levels[0].A = A;
  levelSmootherData(exec, h_->levels[0], options_.eigenSteps);
}

namespace {

/// Pre/post smoothing of A x = b on one level; `zeroGuess` treats x as zero on entry (x is then
/// only written). Chebyshev: the polynomial of Adams et al. (2003) in D^{-1}A on
/// [lambda_max / ratio, lambda_max]; the same polynomial before and after keeps the V-cycle
/// symmetric, so plain CG can use it.
void smooth(const ExecSpace& exec, const Level& L, const AmgOptions& opt, const ConstRealView& b, const RealView& x,
            bool zeroGuess, int sweeps) {
  const lid_t n = L.A.nRows;
  for (int s = 0; s < sweeps; ++s) {
    const bool first = zeroGuess && s == 0;
    if (opt.smoother == AmgSmoother::Jacobi) {
      const double omega = opt.jacobiWeight > 0.0 ? opt.jacobiWeight : 4.0 / (3.0 * L.lambdaMax);
      if (first)
        smootherFirstStep(exec, n, L.invDiag, b, x, L.d, omega);
      else
        smootherStep(exec, L.A, L.invDiag, b, x, L.d, 0.0, omega);
      continue;
    }
    const double lmax = kChebyshevBoost * L.lambdaMax, lmin = lmax / opt.chebyshevRatio;
    const double theta = 0.5 * (lmax + lmin), delta = 0.5 * (lmax - lmin);
    const double sigma = theta / delta;
    double rho = 1.0 / sigma;
    if (first)
      smootherFirstStep(exec, n, L.invDiag, b, x, L.d, 1.0 / theta);
    else
      smootherStep(exec, L.A, L.invDiag, b, x, L.d, 0.0, 1.0 / theta);
    for (int k = 1; k < opt.chebyshevDegree; ++k) {
      const double rhoNew = 1.0 / (2.0 * sigma - rho);
      smootherStep(exec, L.A, L.invDiag, b, x, L.d, rhoNew * rho, 2.0 * rhoNew / delta);
      rho = rhoNew;
    }
  }
}

void coarseDirect(const ExecSpace& exec, const DenseView& inv, const ConstRealView& b, const RealView& x) {
  const lid_t n = static_cast<lid_t>(inv.extent(0));
  Kokkos::parallel_for(
      "mfsi::kernels::amg::coarseSolve", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        double s = 0.0;
        for (lid_t j = 0; j < n; ++j) s += inv(i, j) * b(j);
        x(i) = s;
      });
}

/// x = V-cycle(b) on level l from a zero initial guess.
void vcycle(const ExecSpace& exec, const detail::AmgHierarchy& h, const AmgOptions& opt, std::size_t l,
            const ConstRealView& b, const RealView& x) {
  const Level& L = h.levels[l];
  if (l + 1 == h.levels.size()) {
    if (h.direct)
      coarseDirect(exec, h.coarseInverse, b, x);
    else
      smooth(exec, L, opt, b, x, true, kCoarseSweeps);
    return;
  }
  const Level& C = h.levels[l + 1];
  smooth(exec, L, opt, b, x, true, opt.sweeps);
  residualOnly(exec, L.A, x, b, L.r);
  blas::spmv(exec, L.R, L.r, C.b);
  vcycle(exec, h, opt, l + 1, C.b, C.x);
  blas::spmv(exec, 1.0, L.P, C.x, 1.0, x);
  smooth(exec, L, opt, b, x, false, opt.sweeps);
}

}  // namespace

void AmgPreconditioner::apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) {
  MFSI_CHECK(h_ != nullptr, "amg: apply() before setup()");
  vcycle(exec, *h_, options_, 0, r, z);
}

const CsrMatrix& AmgPreconditioner::levelMatrix(std::size_t l) const {
  MFSI_CHECK(h_ && l < h_->levels.size(), "amg: no level " << l);
  return h_->levels[l].A;
}

const CsrMatrix& AmgPreconditioner::prolongator(std::size_t l) const {
  MFSI_CHECK(h_ && l + 1 < h_->levels.size(), "amg: no prolongator below level " << l);
  return h_->levels[l].P;
}

AmgInfo AmgPreconditioner::info() const {
  AmgInfo out;
  if (!h_) return out;
  double nnz = 0, rows = 0;
  for (const auto& L : h_->levels) {
    out.levels.push_back({L.A.nRows, L.A.nnz(), L.lambdaMax});
    nnz += L.A.nnz();
    rows += L.A.nRows;
  }
  out.operatorComplexity = nnz / h_->levels[0].A.nnz();
  out.gridComplexity = rows / h_->levels[0].A.nRows;
  out.directCoarseSolve = h_->direct;
  return out;
}

}  // namespace mfsi
