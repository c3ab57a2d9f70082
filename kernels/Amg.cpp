#include "kernels/Amg.hpp"

#include "core/Error.hpp"
#include "kernels/CsrBuild.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <type_traits>

namespace mfsi {

namespace {

using DenseView = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>;

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

/// Device CSR with the given sparsity and zero values.
CsrMatrix makeCsr(lid_t nRows, lid_t nCols, const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx,
                  const std::string& label) {
  CsrMatrix M;
  M.nRows = nRows;
  M.nCols = nCols;
  M.rowPtr = toDevice(rowPtr, label + "::rowPtr");
  M.colIdx = toDevice(colIdx, label + "::colIdx");
  std::vector<lid_t> diag(nRows, -1);
  if (nRows == nCols)
    for (lid_t i = 0; i < nRows; ++i) diag[i] = findEntry(rowPtr, colIdx, i, i);
  M.diagIdx = toDevice(diag, label + "::diagIdx");
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

/// The lattice of a host matrix (see detectLattice). Row 0's neighbours give the strides: 1, nx
/// and nx ny on a 3D lattice (its x, y and z neighbours), 1 and nx on a 2D one; then every row
/// must hold exactly the columns its lattice position implies.
AmgLattice latticeOf(const HostCsr& A) {
  const lid_t n = A.nRows;
  if (n < 4 || A.rowPtr.size() != static_cast<std::size_t>(n) + 1) return {};
  std::vector<lid_t> strides;
  for (lid_t k = A.rowPtr[0]; k < A.rowPtr[1]; ++k)
    if (A.colIdx[k] != 0) strides.push_back(A.colIdx[k]);
  AmgLattice g;
  if (strides.size() == 3 && strides[0] == 1 && strides[1] >= 2 && strides[2] % strides[1] == 0 &&
      n % strides[2] == 0) {
    g = {strides[1], strides[2] / strides[1], n / strides[2]};
  } else if (strides.size() == 2 && strides[0] == 1 && strides[1] >= 2 && n % strides[1] == 0) {
    g = {strides[1], n / strides[1], 1};
  } else {
    return {};
  }
  if (g.ny < 2 || (strides.size() == 3 && g.nz < 2)) return {};
  const lid_t sy = g.nx, sz = g.nx * g.ny;
  lid_t expected[7];
  for (lid_t i = 0; i < n; ++i) {
    const lid_t x = i % g.nx, y = (i / g.nx) % g.ny, z = i / sz;
    int m = 0;
    if (z > 0) expected[m++] = i - sz;
    if (y > 0) expected[m++] = i - sy;
    if (x > 0) expected[m++] = i - 1;
    expected[m++] = i;
    if (x + 1 < g.nx) expected[m++] = i + 1;
    if (y + 1 < g.ny) expected[m++] = i + sy;
    if (z + 1 < g.nz) expected[m++] = i + sz;
    if (A.rowPtr[i + 1] - A.rowPtr[i] != m) return {};
    for (int k = 0; k < m; ++k)
      if (A.colIdx[A.rowPtr[i] + k] != expected[k]) return {};
  }
  return g;
}

/// Whether every off-diagonal coupling is strong, |a_ij| >= theta sqrt(|a_ii a_jj|). Cube
/// aggregates assume it: on an anisotropic lattice (stretched cells) the greedy aggregation
/// follows the strong direction, cubes would not.
bool allStrong(const HostCsr& A, double theta) {
  for (lid_t i = 0; i < A.nRows; ++i) {
    const double di = std::abs(A.values[A.diagIdx[i]]);
    for (lid_t k = A.rowPtr[i]; k < A.rowPtr[i + 1]; ++k) {
      const lid_t j = A.colIdx[k];
      const double a = std::abs(A.values[k]), dj = std::abs(A.values[A.diagIdx[j]]);
      if (j != i && !(a * a >= theta * theta * di * dj && a * a > kNegligible * kNegligible * di * dj)) return false;
    }
  }
  return true;
}

/// Lattice-aligned aggregates: f x f x f cubes (f x f on a one-cell-thick lattice), numbered
/// lexicographically on the coarse lattice `coarse` (extents ceil(n / f)). An extent that f does
/// not divide ends with a narrower layer of aggregates rather than a wider one: with f = 2 the
/// restriction rows then stay at most 32 long (a fixed ELL width; three-wide aggregates give 44).
///
/// Why f = 2 on the finest level and 3 below (setup): the 7-point finest operator gives a level-1
/// operator of 33 points (3 x 3 x 3 neighbouring cubes and two more along each axis); 2x2x2
/// cubes of that give a 139-point level 2 (operator complexity 1.88 at 64^3), 3x3x3 cubes a
/// 61-point one (1.61) and the same coarsening ratio as greedy aggregation on those levels
/// (~27-40), but compact and aligned. Measured on the 3D cavity at 64^3 (perf/bench_cavity3d),
/// AMG-CG iterations per step: greedy 8.53; cubes on level 0 only, greedy below 10.0; 2-cubes on
/// levels 0 and 1 8.67, on levels 0-2 7.67; 2-cubes on level 0 and 3-cubes below 7.53.
std::vector<lid_t> latticeAggregates(const AmgLattice& g, AmgLattice& coarse, lid_t& nAgg, lid_t f) {
  coarse = {(g.nx + f - 1) / f, (g.ny + f - 1) / f, (g.nz + f - 1) / f};
  nAgg = coarse.nx * coarse.ny * coarse.nz;
  std::vector<lid_t> agg(static_cast<std::size_t>(g.nx) * g.ny * g.nz);
  for (lid_t z = 0, i = 0; z < g.nz; ++z)
    for (lid_t y = 0; y < g.ny; ++y)
      for (lid_t x = 0; x < g.nx; ++x, ++i) agg[i] = x / f + coarse.nx * (y / f + coarse.ny * (z / f));
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

// ---------------------------------------------------------------------------------------------
// The cycle's operators. The V-cycle runs on copies of every level's operator in its own layout
// and precision (float in mixed precision), refreshed by every set-up and value update:
//  - the smoother works with D^{-1}A: the copy stores the off-diagonal part of D^{-1}A only, and
//    each level keeps its right-hand side scaled, bh = D^{-1} b, and its residual scaled,
//    rh = D^{-1} r. A Chebyshev step d = c1 d + c2 D^{-1} (b - A x) becomes
//    d = c1 d + c2 (bh - x - Ahat x), Ahat = D^{-1}A - I: no diagonal entry, no diagonal read;
//  - so the restriction takes D^{-1}-scaled residuals and returns the next level's scaled
//    right-hand side: R is stored as D_c^{-1} R D (the unscaled R D when the next level is the
//    dense coarsest solve, which wants b itself);
//  - rows of nearly equal length (the finest operator of a hex mesh: 6 off-diagonals; its
//    prolongator: 1-6 entries) are stored padded to a fixed width (ELL). The fixed trip count is
//    unrolled and predicted, where CSR's varying short rows cost a branch miss per row: on one
//    core these kernels are bound by instructions as much as by memory (64^3 Poisson, one
//    thread: 0.8 ms per finest smoother pass in ELL, 1.2 ms in CSR, both float);
//  - a square ELL operator whose rows repeat a few column patterns relative to the row (a
//    structured block: 27 patterns) stores a one-byte pattern id per row instead of its column
//    indices: 25 instead of 48 bytes per finest row and pass, which matters where the finest
//    level streams from DRAM (128^3);
//  - boundary rows of such an operator take the interior pattern where it holds their columns
//    (adoptDominantPattern), so host runs span planes, not lines; the level-1 operator of lattice
//    cubes (32 off-diagonals) is swept in chunks of 8 terms per vectorised pass (RunRows). 64^3
//    cavity, one thread: level-1 smoothing and residuals 10 ms per step (the greedy CSR level 1:
//    ~39 ms); the finest level's smoother pass ~0.35 instead of ~0.44 ms (runs over planes).
// ---------------------------------------------------------------------------------------------

/// Widths with an ELL kernel; a row set whose longest row fits one of them, padded by at most
/// ellMaxPadding(w) entries per row on average, is stored as ELL, otherwise as CSR.
/// 4-8: the finest level of a hex mesh and prolongators; 12 and 32: the off-diagonals of an
/// interior row of the level below a 2D / 3D lattice aggregated into squares / cubes (3 x 3
/// (x 3) neighbouring aggregates and two more along each axis, minus the diagonal), and their
/// restriction rows (an aggregate and the face layer around it: 4 + 8 / 8 + 24).
constexpr int kEllWidths[] = {4, 6, 8, 12, 32};
/// Largest mean padding per row of an ELL layout of width w: 3 entries, or w / 3 (rounded down)
/// for the wide lattice-level widths (boundary rows of a small coarse lattice are up to ~30 % shorter: 8^3;
/// padding costs zeros read in a vectorised sweep, CSR a branch and a column index per entry).
constexpr double ellMaxPadding(int w) { return w / 3 > 3 ? w / 3 : 3.0; }
/// Most distinct column patterns of a pattern-compressed ELL operator (one-byte ids).
constexpr std::size_t kMaxPatterns = 256;
/// Longest run of a pattern-compressed operator: bounds a host thread's unit of work.
constexpr lid_t kMaxRun = 1024;
/// Host backends sweep pattern-compressed operators run by run (vectorisable); device backends
/// row by row (one thread per row, coalesced).
constexpr bool kRunSweeps = kHostExec;
/// Widest pattern whose run sweep keeps all its terms in one loop over rows (RunRows); wider
/// patterns are swept a chunk of 8 (or 6) terms per pass.
[[maybe_unused]] constexpr int kRunUnrolled = 8;  // (nvcc's device pass sees no host branch using it)

template <class S>
using WorkView = Kokkos::View<S*, MemSpace>;
/// Read-only input of a kernel that never writes it (read-only cache path on GPUs).
template <class S>
using ReadView = Kokkos::View<const S*, MemSpace, RandomRead>;
/// Read-only input that the same kernel may also write (own row only): no RandomAccess trait, whose
/// non-coherent cache path must not see data written by the kernel.
template <class S>
using OwnRowView = Kokkos::View<const S*, MemSpace>;

}  // namespace

namespace detail {

/// One operator of the cycle: entries of a set-up matrix (optionally without its diagonal) in
/// ELL (`width` > 0: row i holds [i * width, (i + 1) * width), padded with zeros) or CSR layout,
/// in precision S. `src` maps each stored entry to the set-up matrix's entry (-1: padding; empty:
/// identity), so a value refresh is one pass over the stored entries.
template <class S>
struct AmgCycleOp {
  lid_t nRows = 0;
  int width = 0;
  IndexView rowPtr;  ///< CSR only
  IndexView col;     ///< empty when the columns are given by patterns
  /// ELL with few distinct column patterns (a structured block: one per boundary type): row i's
  /// columns are i + offsets(pattern(i) * width + k). 1 byte per row instead of 4 per entry.
  /// Pattern-compressed values are stored by column, val(k * nRows + i): contiguous in i for the
  /// vectorised host sweeps and coalesced on GPUs.
  Kokkos::View<std::uint8_t*, MemSpace> pattern;
  IndexView offsets;
  /// Pattern-compressed operators only: maximal runs of consecutive rows with one pattern (rows
  /// [runStart(r), runStart(r + 1)) have pattern runPattern(r)), cut at kMaxRun rows. Host
  /// backends sweep a run with the pattern's offsets in registers: contiguous, vectorisable loads.
  IndexView runStart;
  Kokkos::View<std::uint8_t*, MemSpace> runPattern;
  lid_t nRuns = 0;
  IndexView src;
  Kokkos::View<S*, MemSpace> val;
};

/// Operators and work vectors of one level in the cycle's precision S.
template <class S>
struct AmgCycleLevel {
  AmgCycleOp<S> A;  ///< off-diagonal part of D^{-1} A
  AmgCycleOp<S> P;  ///< prolongation from the next level
  AmgCycleOp<S> R;  ///< D_next^{-1} R D (or R D before a dense coarsest solve)
  Kokkos::View<S*, MemSpace> invDiag;
  /// x, y: ping-pong iterates; e: this level's result as a coarse correction; b: scaled
  /// right-hand side D^{-1} b (unscaled on a dense coarsest level); r: scaled residual;
  /// d: Chebyshev direction.
  Kokkos::View<S*, MemSpace> x, y, e, b, r, d;
  /// Kernel labels mfsi::kernels::amg::level<l>::{smoother, residual, restrict, prolong}: the
  /// levels' costs differ by layout, so profiles tell them apart.
  std::string smootherLabel, residualLabel, restrictLabel, prolongLabel;
};

}  // namespace detail

namespace {

/// Boundary rows of a lattice take the pattern of the interior rows (the most frequent one) where
/// it holds all their columns and stays inside the rows: the missing couplings become explicit
/// zeros (src -1), which ELL padding costs anyway. Why: runs of one pattern then span whole
/// planes of the lattice (all but the first and last planes or two), instead of lines cut at
/// every boundary row, and the run sweeps' per-run overhead is paid once per ~1000 rows rather than
/// once per ~30 (level 1 of a 64^3 lattice: 28-row runs). The non-zero terms keep their order, so
/// the sums are those of the exact patterns. `col`, `src`: row-major ELL (col: absolute columns).
void adoptDominantPattern(lid_t n, int w, const std::vector<lid_t>& col, std::vector<lid_t>& src,
                          const std::vector<lid_t>& offsets, std::vector<std::uint8_t>& rowPattern) {
  std::vector<lid_t> count(offsets.size() / w, 0);
  for (lid_t i = 0; i < n; ++i) ++count[rowPattern[i]];
  const int d = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  const lid_t* od = offsets.data() + static_cast<std::size_t>(d) * w;
  for (int k = 1; k < w; ++k)
    if (od[k] <= od[k - 1]) return;  // the dominant pattern is padded itself: no interior
  std::vector<lid_t> rowSrc(w);
  for (lid_t i = 0; i < n; ++i) {
    if (rowPattern[i] == d || i + od[0] < 0 || i + od[w - 1] >= n) continue;
    const std::size_t at = static_cast<std::size_t>(i) * w;
    // Both sorted: merge the row's entries (padding has src -1) into the dominant offsets.
    int kd = 0;
    bool covered = true;
    std::fill(rowSrc.begin(), rowSrc.end(), -1);
    for (int k = 0; k < w && covered; ++k) {
      if (src[at + k] < 0) continue;
      while (kd < w && i + od[kd] < col[at + k]) ++kd;
      covered = kd < w && i + od[kd] == col[at + k];
      if (covered) rowSrc[kd++] = src[at + k];
    }
    if (!covered) continue;
    std::copy(rowSrc.begin(), rowSrc.end(), src.begin() + at);
    rowPattern[i] = static_cast<std::uint8_t>(d);
  }
}

/// Host-side choice of layout for the entries of M kept in a cycle operator.
template <class S>
detail::AmgCycleOp<S> buildCycleOp(const CsrMatrix& M, bool dropDiagonal, const std::string& label) {
  detail::AmgCycleOp<S> op;
  op.nRows = M.nRows;
  const lid_t n = M.nRows;
  const std::vector<lid_t> ptr = hostCopy(M.rowPtr), idx = hostCopy(M.colIdx);
  lid_t kept = 0, longest = 0;
  for (lid_t i = 0; i < n; ++i) {
    lid_t len = 0;
    for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) len += dropDiagonal && idx[k] == i ? 0 : 1;
    kept += len;
    longest = std::max(longest, len);
  }
  for (int w : kEllWidths)
    if (longest <= w && static_cast<double>(w) * n <= kept + ellMaxPadding(w) * n) {
      op.width = w;
      break;
    }
  std::vector<lid_t> col, src;
  if (op.width > 0) {
    col.resize(static_cast<std::size_t>(n) * op.width);
    src.resize(col.size());
    for (lid_t i = 0; i < n; ++i) {
      std::size_t at = static_cast<std::size_t>(i) * op.width;
      const std::size_t end = at + op.width;
      lid_t last = M.nRows == M.nCols ? i : 0;  // padding points at an entry the row reads anyway
      for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) {
        if (dropDiagonal && idx[k] == i) continue;
        col[at] = last = idx[k];
        src[at++] = k;
      }
      for (; at < end; ++at) {
        col[at] = last;
        src[at] = -1;
      }
    }
  } else if (!dropDiagonal) {
    op.rowPtr = M.rowPtr;
    op.col = M.colIdx;
    op.val = WorkView<S>(Kokkos::view_alloc(Kokkos::WithoutInitializing, label + "::values"), M.nnz());
    return op;
  } else {
    std::vector<lid_t> rowPtr(n + 1, 0);
    for (lid_t i = 0; i < n; ++i) {
      for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) {
        if (idx[k] == i) continue;
        col.push_back(idx[k]);
        src.push_back(k);
      }
      rowPtr[i + 1] = static_cast<lid_t>(col.size());
    }
    op.rowPtr = toDevice(rowPtr, label + "::rowPtr");
  }
  if (op.width > 0 && M.nRows == M.nCols) {
    // Column patterns relative to the row; up to kMaxPatterns distinct ones are kept as a table.
    std::map<std::vector<lid_t>, int> ids;
    std::vector<std::uint8_t> rowPattern(n);
    std::vector<lid_t> key(op.width), previous, offsets;
    int id = -1;
    for (lid_t i = 0; i < n && ids.size() <= kMaxPatterns; ++i) {
      for (int k = 0; k < op.width; ++k) key[k] = col[static_cast<std::size_t>(i) * op.width + k] - i;
      if (key != previous) {  // most rows repeat their predecessor's pattern: skip the map
        const auto [it, added] = ids.emplace(key, static_cast<int>(ids.size()));
        if (added) offsets.insert(offsets.end(), key.begin(), key.end());
        id = it->second;
        previous = key;
      }
      rowPattern[i] = static_cast<std::uint8_t>(id);
    }
    if (ids.size() <= kMaxPatterns) {
      adoptDominantPattern(n, op.width, col, src, offsets, rowPattern);
      op.pattern = toDevice(rowPattern, label + "::pattern");
      op.offsets = toDevice(offsets, label + "::offsets");
      col.clear();
      // Values by column (see AmgCycleOp): src follows.
      std::vector<lid_t> byColumn(src.size());
      for (lid_t i = 0; i < n; ++i)
        for (int k = 0; k < op.width; ++k)
          byColumn[static_cast<std::size_t>(k) * n + i] = src[static_cast<std::size_t>(i) * op.width + k];
      src.swap(byColumn);
      std::vector<lid_t> runStart{0};
      std::vector<std::uint8_t> runPattern;
      for (lid_t i = 1; i <= n; ++i)
        if (i == n || rowPattern[i] != rowPattern[i - 1] || i - runStart.back() == kMaxRun) {
          runPattern.push_back(rowPattern[runStart.back()]);
          runStart.push_back(i);
        }
      op.nRuns = static_cast<lid_t>(runPattern.size());
      op.runStart = toDevice(runStart, label + "::runStart");
      op.runPattern = toDevice(runPattern, label + "::runPattern");
    }
  }
  if (!col.empty()) op.col = toDevice(col, label + "::col");
  op.src = toDevice(src, label + "::src");
  op.val = WorkView<S>(Kokkos::view_alloc(Kokkos::WithoutInitializing, label + "::values"), src.size());
  return op;
}

/// op's values from the set-up matrix values m: rowScale(i) * m * colDiag(j) (a scale whose View
/// is empty is 1; colDiag(j) is the diagonal entry m2(diagIdx(j)) of another matrix). Set-up and
/// value updates only.
template <class S>
void refreshCycleOp(const ExecSpace& exec, const detail::AmgCycleOp<S>& op, const RealView& m,
                    const ConstRealView& rowScale, const CsrMatrix* colDiagOf) {
  const ConstIndexView ptr = op.rowPtr, col = op.col, src = op.src, offsets = op.offsets;
  const Kokkos::View<const std::uint8_t*, MemSpace> pattern = op.pattern;
  const bool patterned = pattern.extent(0) > 0;
  const ConstRealView mv = m;
  const ConstRealView dv = colDiagOf ? ConstRealView(colDiagOf->values) : ConstRealView();
  const ConstIndexView di = colDiagOf ? ConstIndexView(colDiagOf->diagIdx) : ConstIndexView();
  const WorkView<S> val = op.val;
  const int w = op.width;
  const lid_t n = op.nRows;
  const bool hasSrc = src.extent(0) > 0, hasRow = rowScale.extent(0) > 0, hasCol = colDiagOf != nullptr;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::cycleValues", RangePolicy(exec, 0, op.nRows), KOKKOS_LAMBDA(lid_t i) {
        const lid_t k0 = w > 0 ? i * w : ptr(i), k1 = w > 0 ? k0 + w : ptr(i + 1);
        const double rs = hasRow ? rowScale(i) : 1.0;
        for (lid_t k = k0; k < k1; ++k) {
          const lid_t e = patterned ? (k - k0) * n + i : k;  // patterned values are stored by column
          const lid_t s = hasSrc ? src(e) : e;
          double v = 0.0;
          if (s >= 0) {
            v = rs * mv(s);
            if (hasCol) v *= dv(di(patterned ? i + offsets(pattern(i) * w + (k - k0)) : col(k)));
          }
          val(e) = static_cast<S>(v);
        }
      });
}

// ---------------------------------------------------------------------------------------------
// Cycle kernels, templated on the scalar S (double, or float in mixed precision) and the layout
// of their operator. Each smoother step is one pass: it reads x from one buffer and writes x + d
// into the other (ping-pong). Each writes its own rows only: deterministic, no atomics.
// ---------------------------------------------------------------------------------------------

/// Layouts with a kernel: CSR, ELL of a width in kEllWidths with explicit columns, or with
/// pattern-compressed columns.
template <int W, bool Patterned>
struct Layout {
  static constexpr int width = W;
  static constexpr bool patterned = Patterned;
};

/// sum_k op(i, k) x(k) over the stored entries of row i.
template <class S, class L>
struct OpRows {
  ConstIndexView rowPtr, col, offsets;
  Kokkos::View<const std::uint8_t*, MemSpace, RandomRead> pattern;
  ReadView<S> val;
  lid_t n;
  explicit OpRows(const detail::AmgCycleOp<S>& op)
      : rowPtr(op.rowPtr), col(op.col), offsets(op.offsets), pattern(op.pattern), val(op.val), n(op.nRows) {}
  template <class X>
  KOKKOS_FORCEINLINE_FUNCTION S sum(lid_t i, const X& x) const {
    constexpr int W = L::width;
    S s = 0;
    if constexpr (W > 0 && L::patterned) {
      const lid_t p = pattern(i) * W;
      for (int k = 0; k < W; ++k) s += val(k * n + i) * x(i + offsets(p + k));
    } else if constexpr (W > 0) {
      const lid_t o = i * W;
      for (int k = 0; k < W; ++k) s += val(o + k) * x(col(o + k));
    } else {
      for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) s += val(k) * x(col(k));
    }
    return s;
  }
};

/// Calls f(Layout<W, patterned>()) for the layout of a cycle operator.
template <class S, class F>
void byLayout(const detail::AmgCycleOp<S>& op, const F& f) {
  const bool pat = op.pattern.extent(0) > 0;
  switch (op.width) {
    case 4:
      return pat ? f(Layout<4, true>()) : f(Layout<4, false>());
    case 6:
      return pat ? f(Layout<6, true>()) : f(Layout<6, false>());
    case 8:
      return pat ? f(Layout<8, true>()) : f(Layout<8, false>());
    case 12:
      return pat ? f(Layout<12, true>()) : f(Layout<12, false>());
    case 32:
      return pat ? f(Layout<32, true>()) : f(Layout<32, false>());
    default:
      return f(Layout<0, false>());
  }
}

/// Host sweeps of a pattern-compressed operator, run by run: within a run the pattern's W offsets
/// and value columns are loop invariants, so row i's terms are contiguous loads at i + offset and
/// the loop over rows vectorises (a row-by-row kernel reloads the offsets through the row's
/// pattern id: an indirect load per term, which the compiler cannot vectorise). Same sums in the
/// same order as OpRows::sum: results are bitwise those of the row kernels.
template <class S, int W>
struct RunRows {
  const lid_t* runStart;
  const std::uint8_t* runPattern;
  const lid_t* offsets;
  const S* val;
  lid_t n;
  explicit RunRows(const detail::AmgCycleOp<S>& op)
      : runStart(op.runStart.data()),
        runPattern(op.runPattern.data()),
        offsets(op.offsets.data()),
        val(op.val.data()),
        n(op.nRows) {}
  /// Calls row(i, s) for every row i of run r, with s = sum_k op(i, k) x(i + offset_k).
  template <class Row>
  void forRows(lid_t r, const S* x, const Row& row) const {
    const lid_t i0 = runStart[r], i1 = runStart[r + 1];
    const lid_t* o = offsets + static_cast<lid_t>(runPattern[r]) * W;
    if constexpr (W > kRunUnrolled) {
      // Wide rows (lattice coarse levels): 2 W streams do not fit in registers, and a loop over
      // them inside the loop over rows does not vectorise. Instead the run's partial sums go
      // through an accumulator in L1, kRunChunk terms per vectorised pass (the same sums in the
      // same order). Measured best: 8 terms per pass for W = 32 (64^3 Poisson AMG-CG, one
      // thread: 7.8 ms per iteration; 4 terms: 9.1 ms, 16: 8.8 ms), 6 for W = 12 (512^2: 7.4 ms
      // per iteration; 4 terms: 8.0 ms, 12: 7.7 ms).
      constexpr int kRunChunk = W % 8 == 0 ? 8 : 6;
      static_assert(W % kRunChunk == 0, "wide run widths are multiples of the chunk");
      S acc[kMaxRun];
      const lid_t m = i1 - i0;
      for (lid_t j = 0; j < m; ++j) acc[j] = 0;
      for (int k0 = 0; k0 < W; k0 += kRunChunk) {
        const S* xk[kRunChunk];
        const S* vk[kRunChunk];
        for (int k = 0; k < kRunChunk; ++k) {
          xk[k] = x + o[k0 + k] + i0;
          vk[k] = val + static_cast<std::size_t>(k0 + k) * n + i0;
        }
        MFSI_IVDEP
        for (lid_t j = 0; j < m; ++j) {
          S s = acc[j];
          for (int k = 0; k < kRunChunk; ++k) s += vk[k][j] * xk[k][j];
          acc[j] = s;
        }
      }
      for (lid_t j = 0; j < m; ++j) row(i0 + j, acc[j]);
      return;
    }
    const S* xk[W];
    const S* vk[W];
    for (int k = 0; k < W; ++k) {
      xk[k] = x + o[k];
      vk[k] = val + static_cast<std::size_t>(k) * n;
    }
    MFSI_IVDEP
    for (lid_t i = i0; i < i1; ++i) {
      S s = 0;
      for (int k = 0; k < W; ++k) s += vk[k][i] * xk[k][i];
      row(i, s);
    }
  }
};

/// SmootherStepKernel over runs (host backends).
template <class S, int W, class T, bool ReadD, bool WriteD>
struct SmootherRunKernel {
  RunRows<S, W> A;
  const S* bh;
  const S* xIn;
  const S* dIn;
  T* xOut;
  S* dOut;
  S c1, c2;
  void operator()(lid_t r) const {
    A.forRows(r, xIn, [&](lid_t i, S s) {
      const S xi = xIn[i];
      const S ri = bh[i] - xi - s;
      S di;
      if constexpr (ReadD)
        di = c1 * dIn[i] + c2 * ri;
      else
        di = c2 * ri;
      xOut[i] = xi + di;
      if constexpr (WriteD) dOut[i] = di;
    });
  }
};

/// ResidualKernel over runs (host backends).
template <class S, int W>
struct ResidualRunKernel {
  RunRows<S, W> A;
  const S* bh;
  const S* x;
  S* r;
  void operator()(lid_t run) const {
    A.forRows(run, x, [&](lid_t i, S s) { r[i] = bh[i] - x[i] - s; });
  }
};

/// Finest level, from a zero guess: bh = D^{-1} b (b is apply()'s double input) and the first
/// smoother step x = c bh (no SpMV).
template <class S>
struct FirstStepKernel {
  ConstRealView b;
  ReadView<S> invDiag;
  WorkView<S> bh, x;
  S c;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t i) const {
    const S bi = static_cast<S>(b(i) * invDiag(i));
    bh(i) = bi;
    x(i) = c * bi;
  }
};

/// One smoother step: d = c1 dIn + c2 (bh - xIn - Ahat xIn) (c1 == 0: dIn is not read),
/// xOut = xIn + d, and dOut = d when dOut is not empty. xOut must not alias xIn; dOut may alias dIn.
template <class S, class L, class XOut>
struct SmootherStepKernel {
  OpRows<S, L> A;
  ReadView<S> bh, xIn;
  OwnRowView<S> dIn;
  XOut xOut;
  WorkView<S> dOut;
  S c1, c2;
  bool readD, writeD;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t i) const {
    const S xi = xIn(i);
    const S ri = bh(i) - xi - A.sum(i, xIn);
    const S di = readD ? c1 * dIn(i) + c2 * ri : c2 * ri;
    xOut(i) = xi + di;
    if (writeD) dOut(i) = di;
  }
};

/// Scaled residual rh = D^{-1} (b - A x) = bh - x - Ahat x.
template <class S, class L>
struct ResidualKernel {
  OpRows<S, L> A;
  ReadView<S> bh, x;
  WorkView<S> r;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t i) const { r(i) = bh(i) - x(i) - A.sum(i, x); }
};

/// Next level's right-hand side b = R' rh (R' = C.R) and, with `first`, its first smoother step
/// from a zero guess x = c b.
template <class S, class L>
struct RestrictKernel {
  OpRows<S, L> R;
  ReadView<S> rh;
  WorkView<S> b, x;
  S c;
  bool first;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t i) const {
    const S s = R.sum(i, rh);
    b(i) = s;
    if (first) x(i) = c * s;
  }
};

/// x += P e (coarse-grid correction).
template <class S, class L>
struct ProlongKernel {
  OpRows<S, L> P;
  ReadView<S> e;
  WorkView<S> x;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t i) const { x(i) += P.sum(i, e); }
};

/// x = A^+ b with the dense pseudo-inverse of the coarsest level, in double in both precisions
/// (a few hundred rows: cheap, and a one-level hierarchy stays the exact inverse).
template <class BIn, class XOut>
void coarseDirect(const ExecSpace& exec, const DenseView& inv, const BIn& b, const XOut& x) {
  using T = typename XOut::non_const_value_type;
  const lid_t n = static_cast<lid_t>(inv.extent(0));
  Kokkos::parallel_for(
      "mfsi::kernels::amg::coarseSolve", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        double s = 0;
        for (lid_t j = 0; j < n; ++j) s += inv(i, j) * b(j);
        x(i) = static_cast<T>(s);
      });
}

/// dst = src, converting the scalar type.
template <class Dst, class Src>
void convert(const ExecSpace& exec, const Src& src, const Dst& dst) {
  using T = typename Dst::non_const_value_type;
  Kokkos::parallel_for(
      "mfsi::kernels::amg::convert", RangePolicy(exec, 0, static_cast<lid_t>(src.extent(0))),
      KOKKOS_LAMBDA(lid_t i) { dst(i) = static_cast<T>(src(i)); });
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The hierarchy.
// ---------------------------------------------------------------------------------------------

struct detail::AmgHierarchy {
  /// Coefficients of one smoother step d = c1 d + c2 D^{-1} (b - A x), x += d.
  struct Step {
    double c1 = 0.0, c2 = 0.0;
  };
  struct Level {
    CsrMatrix A;   ///< this level's operator (level 0: the caller's matrix, shallow)
    CsrMatrix P;   ///< prolongation from the next level (absent on the coarsest)
    CsrMatrix R;   ///< P^T
    CsrMatrix AP;  ///< A P, kept for the value updates of the Galerkin product R (A P)
    IndexView rToP;
    IndexView agg;
    AmgLattice lattice;  ///< this level's lattice when it is aggregated into cubes
    RealView invDiag;
    double lambdaMax = 0.0;
    std::vector<Step> steps;        ///< `sweeps` smoother sweeps (pre- and post-smoothing)
    std::vector<Step> coarseSteps;  ///< kCoarseSweeps sweeps (coarsest level without direct solve)
  };
  std::vector<Level> levels;
  DenseView coarseInverse;
  bool direct = false;
  std::vector<AmgCycleLevel<double>> cycleDouble;  ///< AmgPrecision::Double
  std::vector<AmgCycleLevel<float>> cycleMixed;    ///< AmgPrecision::Mixed
};

AmgPreconditioner::AmgPreconditioner(const AmgOptions& options) : options_(options) {
  MFSI_CHECK(options.sweeps >= 1 && options.finestSweeps >= 0, "amg: sweeps must be >= 1 and finestSweeps >= 0");
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
using Step = detail::AmgHierarchy::Step;

/// Step coefficients of `sweeps` smoother applications, each a polynomial in D^{-1}A (so the
/// same polynomial before and after the coarse correction keeps the V-cycle symmetric and plain
/// CG can use it). Every step is d = c1 d + c2 D^{-1} (b - A x), x += d.
///  - ChebyshevFourthKind (Lottes 2023, "Optimal polynomial smoothers for multigrid V-cycles",
///    the 4th-kind recurrence): on [0, rho] with rho = the boosted lambda_max,
///    d_0 = 4 / (3 rho) D^{-1} r_0, d_k = (2k - 1) / (2k + 3) d_{k-1} + (8k + 4) / ((2k + 3) rho)
///    D^{-1} r_k. It minimises the V-cycle's error bound over the whole of [0, rho] instead of
///    damping [rho / ratio, rho] only, and needs no lower bound.
///  - Chebyshev: the first-kind polynomial of Adams et al. (2003) on [rho / ratio, rho].
std::vector<Step> smootherSteps(double lambdaMax, const AmgOptions& opt, int sweeps) {
  std::vector<Step> steps;
  const double rho = kChebyshevBoost * lambdaMax;
  for (int s = 0; s < sweeps; ++s) {
    switch (opt.smoother) {
      case AmgSmoother::Jacobi:
        steps.push_back({0.0, opt.jacobiWeight > 0.0 ? opt.jacobiWeight : 4.0 / (3.0 * lambdaMax)});
        break;
      case AmgSmoother::ChebyshevFourthKind:
        steps.push_back({0.0, 4.0 / (3.0 * rho)});
        for (int k = 1; k < opt.chebyshevDegree; ++k)
          steps.push_back({(2.0 * k - 1.0) / (2.0 * k + 3.0), (8.0 * k + 4.0) / ((2.0 * k + 3.0) * rho)});
        break;
      case AmgSmoother::Chebyshev: {
        const double lmin = rho / opt.chebyshevRatio;
        const double theta = 0.5 * (rho + lmin), delta = 0.5 * (rho - lmin);
        const double sigma = theta / delta;
        double r = 1.0 / sigma;
        steps.push_back({0.0, 1.0 / theta});
        for (int k = 1; k < opt.chebyshevDegree; ++k) {
          const double rNew = 1.0 / (2.0 * sigma - r);
          steps.push_back({rNew * r, 2.0 * rNew / delta});
          r = rNew;
        }
        break;
      }
    }
  }
  return steps;
}

/// Smoother applications on level l.
int levelSweeps(const AmgOptions& opt, std::size_t l) {
  return l == 0 && opt.finestSweeps > 0 ? opt.finestSweeps : opt.sweeps;
}

/// Diagonal inverse, lambda_max(D^{-1} A) and smoother coefficients of level l (values only).
void levelSmootherData(const ExecSpace& exec, Level& L, std::size_t l, const AmgOptions& opt) {
  invertDiagonal(exec, L.A, L.invDiag);
  L.lambdaMax = estimateLambdaMax(exec, L.A, L.invDiag, opt.eigenSteps);
  MFSI_CHECK(L.lambdaMax > 0.0 && std::isfinite(L.lambdaMax),
             "amg: could not estimate the spectral radius (rows " << L.A.nRows << ", estimate " << L.lambdaMax << ")");
  L.steps = smootherSteps(L.lambdaMax, opt, levelSweeps(opt, l));
  L.coarseSteps = smootherSteps(L.lambdaMax, opt, kCoarseSweeps);
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

/// Whether level l's right-hand side is kept scaled by D^{-1} (all but a dense coarsest level).
bool scaledRhs(const detail::AmgHierarchy& h, std::size_t l) { return !(h.direct && l + 1 == h.levels.size()); }

/// The cycle's values of level l from the set-up's double values. `finestRefresh`: only what
/// depends on the finest operator's own values (updateFinestSmoother): D^{-1}, the smoother's
/// operator, and the restriction's right scaling by D.
template <class S>
void syncCycleValues(const ExecSpace& exec, const detail::AmgHierarchy& h, detail::AmgCycleLevel<S>& C, std::size_t l,
                     bool finestRefresh) {
  const Level& L = h.levels[l];
  if constexpr (std::is_same<S, double>::value)
    C.invDiag = L.invDiag;
  else
    convert(exec, ConstRealView(L.invDiag), C.invDiag);
  refreshCycleOp(exec, C.A, L.A.values, L.invDiag, nullptr);
  if (l + 1 == h.levels.size()) return;
  const ConstRealView rowScale = scaledRhs(h, l + 1) ? ConstRealView(h.levels[l + 1].invDiag) : ConstRealView();
  refreshCycleOp(exec, C.R, L.R.values, rowScale, &L.A);
  if (!finestRefresh) refreshCycleOp(exec, C.P, L.P.values, ConstRealView(), nullptr);
}

/// Operators and work vectors of the cycle in precision S (set-up only), then its values.
template <class S>
void buildCycle(const ExecSpace& exec, const detail::AmgHierarchy& h, std::vector<detail::AmgCycleLevel<S>>& cycle) {
  cycle.assign(h.levels.size(), {});
  for (std::size_t l = 0; l < h.levels.size(); ++l) {
    auto& C = cycle[l];
    const Level& L = h.levels[l];
    const lid_t n = L.A.nRows;
    const std::string pre = "mfsi::kernels::amg::level" + std::to_string(l) + "::cycle::";
    C.A = buildCycleOp<S>(L.A, true, pre + "A");
    const std::string kernel = "mfsi::kernels::amg::level" + std::to_string(l) + "::";
    C.smootherLabel = kernel + "smoother";
    C.residualLabel = kernel + "residual";
    C.restrictLabel = kernel + "restrict";
    C.prolongLabel = kernel + "prolong";
    if (l + 1 < h.levels.size()) {
      C.P = buildCycleOp<S>(L.P, false, pre + "P");
      C.R = buildCycleOp<S>(L.R, false, pre + "R");
    }
    auto vec = [&](const char* what) { return WorkView<S>(pre + what, n); };
    if (!std::is_same<S, double>::value) C.invDiag = vec("invDiag");
    C.x = vec("x");
    C.y = vec("y");
    C.r = vec("r");
    C.d = vec("d");
    C.b = vec("b");
    if (l > 0) C.e = vec("e");
  }
  for (std::size_t l = 0; l < h.levels.size(); ++l) syncCycleValues(exec, h, cycle[l], l, false);
}

/// Builds (`rebuild`: set-up) or refreshes the values of the cycle of the chosen precision.
void syncCycle(const ExecSpace& exec, detail::AmgHierarchy& h, AmgPrecision precision, bool rebuild) {
  auto sync = [&](auto& cycle) {
    if (rebuild) return buildCycle(exec, h, cycle);
    for (std::size_t l = 0; l < h.levels.size(); ++l) syncCycleValues(exec, h, cycle[l], l, false);
  };
  if (precision == AmgPrecision::Double)
    sync(h.cycleDouble);
  else
    sync(h.cycleMixed);
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
    lv[l].invDiag = RealView("mfsi::kernels::amg::level" + std::to_string(l) + "::invDiag", lv[l].A.nRows);
    levelSmootherData(exec, lv[l], l, options_);
    const lid_t n = lv[l].A.nRows;
    if (n <= options_.coarseSize || static_cast<int>(l) + 1 >= options_.maxLevels) break;

    exec.fence();
    const HostCsr a = hostCopy(lv[l].A);
    lid_t nc = 0;
    std::vector<lid_t> agg;
    const bool cubes = options_.aggregation == AmgAggregation::Auto && static_cast<int>(l) < options_.latticeLevels;
    if (cubes && l == 0) {
      lv[0].lattice = latticeOf(a);
      if (lv[0].lattice.valid() && !allStrong(a, options_.strengthThreshold)) lv[0].lattice = {};
    }
    if (!cubes) lv[l].lattice = {};  // kept only on levels aggregated into cubes
    AmgLattice coarseLattice;
    if (lv[l].lattice.valid())
      agg = latticeAggregates(lv[l].lattice, coarseLattice, nc, l == 0 ? 2 : 3);
    else
      agg = aggregate(a, l == 0 ? options_.strengthThreshold : 0.0, nc);
    // Stop when coarsening stalls (e.g. no couplings left): the coarsest level takes over. Also
    // rather than coarsen a level that is solved directly anyway into a single aggregate: on a
    // singular (Neumann) system its 1 x 1 operator is the null space's rounding left-over, which
    // the relative cut of the pseudo-inverse cannot tell from a true eigenvalue.
    if (nc == 0 || nc > n - n / 8 || (nc == 1 && n <= options_.maxDirectSize)) break;

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
    lv[l].agg = toDevice(agg, pre + "::aggregate");
    lv[l].P = makeCsr(n, nc, pPtr, pIdx, pre + "::P");
    lv[l].R = makeCsr(nc, n, rPtr, rIdx, pre + "::R");
    lv[l].rToP = toDevice(rToP, pre + "::rToP");
    lv[l].AP = makeCsr(n, nc, apPtr, apIdx, pre + "::AP");
    Level next;
    next.lattice = coarseLattice;
    next.A = makeCsr(nc, nc, cPtr, cIdx, "mfsi::kernels::amg::level" + std::to_string(l + 1) + "::A");
    lv.push_back(next);
    levelTransferValues(exec, lv[l], lv[l + 1], options_);
  }
  coarsestInverse(exec, *h_, options_.maxDirectSize);
  syncCycle(exec, *h_, options_.precision, true);
}

void AmgPreconditioner::updateValues(const ExecSpace& exec, const CsrMatrix& A) {
  if (!h_ || !sameSparsity(exec, h_->levels[0].A, A)) return setup(exec, A);
  ScopedRegion region("mfsi::kernels::amg::updateValues");
  auto& lv = h_->levels;
  lv[0].A = A;
  for (std::size_t l = 0; l < lv.size(); ++l) {
    levelSmootherData(exec, lv[l], l, options_);
    if (l + 1 < lv.size()) levelTransferValues(exec, lv[l], lv[l + 1], options_);
  }
  coarsestInverse(exec, *h_, options_.maxDirectSize);
  syncCycle(exec, *h_, options_.precision, false);
}

void AmgPreconditioner::updateFinestSmoother(const ExecSpace& exec, const CsrMatrix& A) {
  MFSI_CHECK(h_ && sameSparsity(exec, h_->levels[0].A, A),
             "amg: updateFinestSmoother() needs a set-up on the same sparsity");
  ScopedRegion region("mfsi::kernels::amg::updateFinestSmoother");
  auto& L = h_->levels[0];
  L.A = A;
  levelSmootherData(exec, L, 0, options_);
  if (options_.precision == AmgPrecision::Double)
    syncCycleValues(exec, *h_, h_->cycleDouble[0], 0, true);
  else
    syncCycleValues(exec, *h_, h_->cycleMixed[0], 0, true);
}

namespace {

/// Smoother steps [first, steps.size()) on level L from x in `cur` (and the previous direction in
/// `dIn`). Returns the ping-pong buffer holding the result, or, with `toOut`, writes the last step
/// into `out` (the level's result: apply()'s double z on the finest level).
template <class S, class Out>
WorkView<S> runSteps(const ExecSpace& exec, const detail::AmgCycleLevel<S>& C, const std::vector<Step>& steps,
                     std::size_t first, WorkView<S> cur, OwnRowView<S> dIn, const Out& out, bool toOut) {
  if (first == steps.size()) {
    if (toOut) convert(exec, ReadView<S>(cur), out);
    return cur;
  }
  for (std::size_t j = first; j < steps.size(); ++j) {
    const bool last = j + 1 == steps.size();
    const WorkView<S> dOut = !last && steps[j + 1].c1 != 0.0 ? C.d : WorkView<S>();
    const S c1 = static_cast<S>(steps[j].c1), c2 = static_cast<S>(steps[j].c2);
    const bool readD = steps[j].c1 != 0.0, writeD = dOut.extent(0) > 0;
    const WorkView<S> next = cur.data() == C.x.data() ? C.y : C.x;
    byLayout(C.A, [&](auto layout) {
      using L = decltype(layout);
      if constexpr (L::patterned && kRunSweeps) {
        const RangePolicy runs(exec, 0, C.A.nRuns);
        auto sweep = [&](auto* xOut, auto readTag, auto writeTag) {
          using T = std::remove_pointer_t<decltype(xOut)>;
          Kokkos::parallel_for(C.smootherLabel, runs,
                               SmootherRunKernel<S, L::width, T, decltype(readTag)::value, decltype(writeTag)::value>{
                                   RunRows<S, L::width>(C.A), C.b.data(), cur.data(), dIn.data(), xOut,
                                   dOut.data(), c1, c2});
        };
        auto dispatch = [&](auto* xOut) {
          if (readD && writeD) return sweep(xOut, std::true_type(), std::true_type());
          if (readD) return sweep(xOut, std::true_type(), std::false_type());
          if (writeD) return sweep(xOut, std::false_type(), std::true_type());
          return sweep(xOut, std::false_type(), std::false_type());
        };
        if (last && toOut)
          dispatch(out.data());
        else
          dispatch(next.data());
        return;
      }
      const RangePolicy policy(exec, 0, C.A.nRows);
      if (last && toOut)
        Kokkos::parallel_for(
            C.smootherLabel, policy,
            SmootherStepKernel<S, L, Out>{OpRows<S, L>(C.A), C.b, cur, dIn, out, dOut, c1, c2, readD, writeD});
      else
        Kokkos::parallel_for(
            C.smootherLabel, policy,
            SmootherStepKernel<S, L, WorkView<S>>{OpRows<S, L>(C.A), C.b, cur, dIn, next, dOut, c1, c2, readD, writeD});
    });
    if (last && toOut) return cur;
    cur = next;
    dIn = C.d;
  }
  return cur;
}

/// out = V-cycle on level l from a zero initial guess, given the level's scaled right-hand side
/// in C.b and the first smoother step from zero in C.x (written by the previous kernel: the
/// finest level's conversion of apply()'s input, or the restriction).
template <class S, class Out>
void vcycle(const ExecSpace& exec, const detail::AmgHierarchy& h, const std::vector<detail::AmgCycleLevel<S>>& cycle,
            std::size_t l, const Out& out) {
  const Level& L = h.levels[l];
  const auto& C = cycle[l];
  // After the first step from zero, x = d: the next step reads its direction from x.
  if (l + 1 == h.levels.size()) {
    runSteps<S>(exec, C, L.coarseSteps, 1, C.x, C.x, out, true);
    return;
  }
  const WorkView<S> x = runSteps<S>(exec, C, L.steps, 1, C.x, C.x, out, false);
  byLayout(C.A, [&](auto layout) {
    using L = decltype(layout);
    if constexpr (L::patterned && kRunSweeps)
      Kokkos::parallel_for(C.residualLabel, RangePolicy(exec, 0, C.A.nRuns),
                           ResidualRunKernel<S, L::width>{RunRows<S, L::width>(C.A), C.b.data(), x.data(), C.r.data()});
    else
      Kokkos::parallel_for(C.residualLabel, RangePolicy(exec, 0, C.A.nRows),
                           ResidualKernel<S, L>{OpRows<S, L>(C.A), C.b, x, C.r});
  });
  const auto& N = cycle[l + 1];
  const bool nextDirect = !scaledRhs(h, l + 1);
  const Level& LN = h.levels[l + 1];
  const double c = nextDirect ? 0.0 : (l + 2 == h.levels.size() ? LN.coarseSteps : LN.steps)[0].c2;
  byLayout(C.R, [&](auto layout) {
    using L = decltype(layout);
    Kokkos::parallel_for(C.restrictLabel, RangePolicy(exec, 0, C.R.nRows),
                         RestrictKernel<S, L>{OpRows<S, L>(C.R), C.r, N.b, N.x, static_cast<S>(c), !nextDirect});
  });
  if (nextDirect)
    coarseDirect(exec, h.coarseInverse, ReadView<S>(N.b), N.e);
  else
    vcycle<S>(exec, h, cycle, l + 1, N.e);
  byLayout(C.P, [&](auto layout) {
    using L = decltype(layout);
    Kokkos::parallel_for(C.prolongLabel, RangePolicy(exec, 0, C.P.nRows),
                         ProlongKernel<S, L>{OpRows<S, L>(C.P), N.e, x});
  });
  runSteps<S>(exec, C, L.steps, 0, x, C.d, out, true);
}

template <class S>
void applyCycle(const ExecSpace& exec, const detail::AmgHierarchy& h,
                const std::vector<detail::AmgCycleLevel<S>>& cycle, const ConstRealView& r, const RealView& z) {
  if (!scaledRhs(h, 0)) {
    coarseDirect(exec, h.coarseInverse, r, z);
    return;
  }
  const auto& C = cycle[0];
  const Level& L = h.levels[0];
  const double c = (h.levels.size() == 1 ? L.coarseSteps : L.steps)[0].c2;
  Kokkos::parallel_for("mfsi::kernels::amg::smootherFirst", RangePolicy(exec, 0, L.A.nRows),
                       FirstStepKernel<S>{r, C.invDiag, C.b, C.x, static_cast<S>(c)});
  vcycle<S>(exec, h, cycle, 0, z);
}

}  // namespace

void AmgPreconditioner::setFinestSweeps(int sweeps) {
  MFSI_CHECK(sweeps >= 0, "amg: finestSweeps must be >= 0 (0: sweeps)");
  options_.finestSweeps = sweeps;
  if (h_ != nullptr) {
    auto& L = h_->levels[0];
    L.steps = smootherSteps(L.lambdaMax, options_, levelSweeps(options_, 0));
  }
}

void AmgPreconditioner::apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) {
  MFSI_CHECK(h_ != nullptr, "amg: apply() before setup()");
  if (options_.precision == AmgPrecision::Double)
    applyCycle(exec, *h_, h_->cycleDouble, r, z);
  else
    applyCycle(exec, *h_, h_->cycleMixed, r, z);
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
  auto cycleLayouts = [&](const auto& cycle) {
    for (std::size_t l = 0; l < cycle.size() && l < out.levels.size(); ++l) {
      out.levels[l].cycleWidth = cycle[l].A.width;
      out.levels[l].cyclePatterned = cycle[l].A.pattern.extent(0) > 0;
    }
  };
  for (const auto& L : h_->levels) {
    AmgLevelInfo li;
    li.rows = L.A.nRows;
    li.nnz = L.A.nnz();
    li.lambdaMax = L.lambdaMax;
    if (L.agg.extent(0) > 0) li.lattice = L.lattice;
    out.levels.push_back(li);
    nnz += L.A.nnz();
    rows += L.A.nRows;
  }
  if (options_.precision == AmgPrecision::Double)
    cycleLayouts(h_->cycleDouble);
  else
    cycleLayouts(h_->cycleMixed);
  out.operatorComplexity = nnz / h_->levels[0].A.nnz();
  out.gridComplexity = rows / h_->levels[0].A.nRows;
  out.directCoarseSolve = h_->direct;
  return out;
}

AmgLattice detectLattice(const CsrMatrix& A) {
  if (A.nRows != A.nCols) return {};
  Kokkos::fence();
  return latticeOf(hostCopy(A));
}

}  // namespace mfsi
