#pragma once
/// \file
/// \brief Vector and sparse-matrix kernels of the linear solvers: SpMV, dot products, axpy/axpby,
/// norms, and fused combinations (e.g. `r = b - A x` together with `r.r`).
///
/// Reductions are deterministic: a vector is cut into fixed blocks of `kReductionBlock` rows,
/// each block is summed serially by one thread, and the block sums are added on the host in block
/// order. The result depends only on the data, never on the number of threads or the backend's
/// reduction tree, so a run is bitwise repeatable (tests compare solver iteration counts exactly).
///
/// Distributed-memory design: every rank owns rows [0, nRows) and holds ghost entries
/// [nRows, nCols) of the vectors it multiplies. A distributed solve adds exactly two things,
/// both behind `SolverComm`: `updateGhosts` before each SpMV and `globalSum` after each local
/// reduction. On one rank both are no-ops.
#include "core/parallel/Halo.hpp"
#include "kernels/CsrMatrix.hpp"

#include <mpi.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace mfsi {

/// \brief The rank-decomposition hooks of the linear algebra. One rank (the default): sums are
/// local and there are no ghosts. Over an MPI communicator, sums gather every rank's partials and
/// add them in rank order on every rank, so a reduction is bitwise the same on all ranks and from
/// run to run at a given rank count (an MPI_Allreduce may pick its summation order by message
/// size); ghost updates go through the cells' halo exchange (core/parallel/Halo).
class SolverComm {
 public:
  SolverComm() = default;
  /// \brief Reductions over `comm`; ghost updates through `halo` (null: no ghosts). The halo must
  /// outlive this object.
  SolverComm(MPI_Comm comm, const Halo* halo);

  int ranks() const { return size_; }
  /// \brief Sum `n` per-rank partial sums over all ranks, in place.
  void globalSum(double* values, int n) const {
    if (size_ > 1) gatherSum(values, n);
  }
  /// \brief Sum one per-rank partial sum over all ranks.
  double globalSum(double local) const {
    globalSum(&local, 1);
    return local;
  }
  /// \brief Collective reductions (sums and maxima over more than one rank) this process has
  /// made so far, over every SolverComm: the latency count of the scaling model (perf/).
  static std::int64_t reductions();
  /// \brief Wall seconds spent in those reductions (the messages and any wait for a rank still
  /// computing).
  static double reductionSeconds();
  /// \brief Maximum of a per-rank value over all ranks.
  double globalMax(double local) const { return size_ > 1 ? reduceMax(local) : local; }
  /// \brief Refresh ghost entries [nRows, nCols) of `x` before it is multiplied by a matrix.
  void updateGhosts(const ExecSpace& exec, const RealView& x) const {
    if (halo_ != nullptr) halo_->exchange(exec, x);
  }
  /// \brief Same for the rows [nRows, nCols) of an n x 3 multi-vector (one exchange for all three).
  void updateGhosts(const ExecSpace& exec, const Real3View& x) const {
    if (halo_ != nullptr) halo_->exchange(exec, x);
  }
  /// \brief `updateGhosts` in two halves (Halo::begin and Halo::end), for a product that
  /// multiplies its interior rows in between (blas::spmvDotOverlapped).
  void beginGhosts(const ExecSpace& exec, const RealView& x) const {
    if (halo_ != nullptr) halo_->begin(exec, x);
  }
  void endGhosts(const ExecSpace& exec, const RealView& x) const {
    if (halo_ != nullptr) halo_->end(exec, x);
  }
  /// \brief Whether products overlap their ghost updates with their interior rows
  /// (blas::spmvDotOverlapped): there are ghosts, and `setOverlap` has not turned it off.
  bool overlapsGhosts() const { return overlap_ && halo_ != nullptr && halo_->neighbours() > 0; }
  /// \brief Overlap ghost updates with interior work (the default) or not (the same results, bit
  /// for bit; for comparisons in perf/).
  void setOverlap(bool on) { overlap_ = on; }

 private:
  void gatherSum(double* values, int n) const;
  double reduceMax(double local) const;

  MPI_Comm comm_ = MPI_COMM_NULL;
  int size_ = 1;
  const Halo* halo_ = nullptr;
  bool overlap_ = true;
};

namespace blas {

/// \brief Rows per block of a deterministic reduction (see the file comment).
inline constexpr lid_t kReductionBlock = kRowBlock;

/// \brief N running sums carried through a fused reduction body.
template <int N>
struct Sums {
  double v[N];
  KOKKOS_INLINE_FUNCTION double& operator[](int k) { return v[k]; }
  KOKKOS_INLINE_FUNCTION const double& operator[](int k) const { return v[k]; }
};

/// \brief One row's terms of OpenFOAM's scaled residual, given b_i, (A x)_i and the row sum
/// rs_i = sum_j a_ij: returns r_i = b_i - (A x)_i and adds {|r_i|, |ax - rs xbar| + |b - rs xbar|
/// (the normalisation factor), |b| + |ax| (round-off scale), r_i^2} to acc[0..3].
KOKKOS_INLINE_FUNCTION double scaledResidualTerms(double b, double ax, double rs, double xbar, Sums<4>& acc) {
  const double r = b - ax;
  acc[0] += kmath::fabs(r);
  acc[1] += kmath::fabs(ax - rs * xbar) + kmath::fabs(b - rs * xbar);
  acc[2] += kmath::fabs(b) + kmath::fabs(ax);
  acc[3] += r * r;
  return r;
}

/// \brief Lanes of `reduceLanes`: independent partial sums per block (see there).
inline constexpr int kReductionLanes = 4;

/// Sums `s[0..L)` of one block combined pairwise in a fixed order: ((s0 + s1) + (s2 + s3)) for L = 4.
template <int N, int L>
KOKKOS_INLINE_FUNCTION void combineLanes(Sums<N> (&s)[L]) {
  for (int w = 1; w < L; w *= 2)
    for (int l = 0; l + w < L; l += 2 * w)
      for (int k = 0; k < N; ++k) s[l][k] += s[l + w][k];
}

/// \brief `reduce` with L interleaved partial sums per block: row i of a block goes to lane
/// (i - blockStart) % L, and the lanes are combined pairwise in a fixed order. Deterministic like
/// `reduce` (the order depends on n only), but a different order: results differ from `reduce`'s
/// by rounding. Why: with one sum (a dot product), `reduce`'s running sum per block is a chain of
/// dependent adds, one per row, which bounds a pass over cached vectors; L chains run in
/// parallel. Measured on this machine (one thread, 262,144 rows in cache, g++ -O3): a dot 0.177
/// -> 0.054 ms with 4 lanes; with 2-3 sums per row (CG's update and r.z passes), which already
/// are independent chains, no gain (r.z 0.177 -> 0.18-0.20 ms, the update 0.21 -> 0.27 ms).
template <int N, int L = kReductionLanes, class Body>
std::array<double, N> reduceLanes(const ExecSpace& exec, const SolverComm& comm, const std::string& label, lid_t n,
                                  const Body& body) {
  static_assert(L >= 1 && (L & (L - 1)) == 0 && kReductionBlock % L == 0, "reduceLanes: L a power of two");
  const lid_t bs = kReductionBlock;
  const lid_t nBlocks = (n + bs - 1) / bs;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> partial(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, label + "::partials"), nBlocks, N);
  Kokkos::parallel_for(
      label, RangePolicy(exec, 0, nBlocks), KOKKOS_LAMBDA(lid_t blk) {
        Sums<N> s[L];
        for (int l = 0; l < L; ++l)
          for (int k = 0; k < N; ++k) s[l][k] = 0.0;
        const lid_t begin = blk * bs;
        const lid_t end = begin + bs < n ? begin + bs : n;
        lid_t i = begin;
        for (; i + L <= end; i += L)
          for (int l = 0; l < L; ++l) body(i + l, s[l]);
        for (int l = 0; i < end; ++i, ++l) body(i, s[l]);
        combineLanes<N, L>(s);
        for (int k = 0; k < N; ++k) partial(blk, k) = s[0][k];
      });
  auto host = Kokkos::create_mirror_view(partial);
  Kokkos::deep_copy(exec, host, partial);
  exec.fence();
  std::array<double, N> out{};
  for (lid_t b = 0; b < nBlocks; ++b)
    for (int k = 0; k < N; ++k) out[k] += host(b, k);
  comm.globalSum(out.data(), N);
  return out;
}

/// \brief Deterministic fused reduction: calls `body(i, sums)` for i in [0, n) (a device
/// lambda/functor adding its contributions to `Sums<N>& sums`), returns the N global sums.
/// Blocks of `kReductionBlock` rows are summed in order by one thread each (`reduceLanes` with
/// one lane); block sums are added in block order on the host, then `comm.globalSum` combines the
/// ranks. Fences `exec`.
template <int N, class Body>
std::array<double, N> reduce(const ExecSpace& exec, const SolverComm& comm, const std::string& label, lid_t n,
                             const Body& body) {
  return reduceLanes<N, 1>(exec, comm, label, n, body);
}

// ---------------------------------------------------------------------------------------------
// Host sweeps over the row runs of a matrix (CsrRowRuns): within a run the column offsets are loop
// invariants and every row has the same length, so the loads of x are at i + offset (contiguous)
// and no column index is read. Each row sums its terms in column order, as the row kernels do,
// and reduceRuns adds the per-row contributions row by row in block order, as `reduce` does: the
// results are bitwise those of the row kernels. Used only where kHostExec (host backends); device
// backends keep the row kernels.
// ---------------------------------------------------------------------------------------------
namespace detail {

/// Host range policy on `exec` where it is a host instance (never launched on device builds).
template <class E>
Kokkos::RangePolicy<HostExecSpace> hostPolicy(const E& exec, lid_t begin, lid_t end) {
  if constexpr (std::is_same<E, HostExecSpace>::value)
    return Kokkos::RangePolicy<HostExecSpace>(exec, begin, end);
  else
    return Kokkos::RangePolicy<HostExecSpace>(begin, end);
}

/// Host pointers to a matrix's runs and values (V: the values' type; a float copy of a matrix's
/// values shares its sparsity and runs).
template <class V>
struct RunViewOf {
  const lid_t* start = nullptr;
  const lid_t* offsetsAt = nullptr;
  const lid_t* offsets = nullptr;
  const lid_t* rowPtr = nullptr;
  const V* val = nullptr;
  RunViewOf() = default;
  RunViewOf(const CsrRowRuns& runs, const IndexView& ptr, const V* values)
      : start(runs.start.data()),
        offsetsAt(runs.offsetsAt.data()),
        offsets(runs.offsets.data()),
        rowPtr(ptr.data()),
        val(values) {}
};

struct RunView : RunViewOf<double> {
  RunView() = default;
  explicit RunView(const CsrMatrix& A) : RunViewOf<double>(A.runs, A.rowPtr, A.values.data()) {}
};

/// Calls row(i, v, off, w) for every row i of run r: v points at row i's w values, whose columns
/// are i + off[k]. w is std::integral_constant<int, 7> for 7-entry rows (the interior of a hex
/// block; the loop over k unrolls) and an int otherwise.
template <class V, class Row>
inline void forRunRows(const RunViewOf<V>& R, lid_t r, const Row& row) {
  const lid_t i0 = R.start[r], i1 = R.start[r + 1];
  const lid_t w = R.rowPtr[i0 + 1] - R.rowPtr[i0];
  const lid_t* off = R.offsets + R.offsetsAt[r];
  const V* v = R.val + R.rowPtr[i0] - static_cast<std::ptrdiff_t>(i0) * w;
  if (w == 7) {
    MFSI_IVDEP
    for (lid_t i = i0; i < i1; ++i)
      row(i, v + static_cast<std::ptrdiff_t>(i) * 7, off, std::integral_constant<int, 7>());
  } else {
    for (lid_t i = i0; i < i1; ++i) row(i, v + static_cast<std::ptrdiff_t>(i) * w, off, static_cast<int>(w));
  }
}

/// sum_k v[k] x[i + off[k]]: one row of A x inside forRunRows, in the row kernels' order.
template <class S, class Width>
inline S runRowDot(const S* v, const S* x, lid_t i, const lid_t* off, Width width) {
  S s = 0;
  for (int k = 0; k < width; ++k) s += v[k] * x[i + off[k]];
  return s;
}

/// Host `reduceLanes` with a per-block pass first: per block [b0, b1) of kRowBlock rows,
/// blockBody(b0, b1) (e.g. a vectorised sweep writing per-row results), then rowSum(i, sums) for
/// its rows in `reduceLanes`' lane order: the same sums as `reduceLanes` of the fused row body.
template <int N, int L, class BlockBody, class RowSum>
std::array<double, N> reduceHostLanes(const ExecSpace& exec, const SolverComm& comm, const std::string& label, lid_t n,
                                      const BlockBody& blockBody, const RowSum& rowSum) {
  const lid_t bs = kRowBlock;
  const lid_t nBlocks = (n + bs - 1) / bs;
  std::vector<double> partial(static_cast<std::size_t>(nBlocks) * N);
  double* part = partial.data();
  exec.fence();
  Kokkos::parallel_for(label, hostPolicy(exec, 0, nBlocks), [=](lid_t blk) {
    const lid_t begin = blk * bs;
    const lid_t end = begin + bs < n ? begin + bs : n;
    blockBody(begin, end);
    Sums<N> s[L];
    for (int l = 0; l < L; ++l)
      for (int k = 0; k < N; ++k) s[l][k] = 0.0;
    lid_t i = begin;
    for (; i + L <= end; i += L)
      for (int l = 0; l < L; ++l) rowSum(i + l, s[l]);
    for (int l = 0; i < end; ++i, ++l) rowSum(i, s[l]);
    combineLanes<N, L>(s);
    for (int k = 0; k < N; ++k) part[static_cast<std::size_t>(blk) * N + k] = s[0][k];
  });
  HostExecSpace().fence();
  std::array<double, N> out{};
  for (lid_t b = 0; b < nBlocks; ++b)
    for (int k = 0; k < N; ++k) out[k] += part[static_cast<std::size_t>(b) * N + k];
  comm.globalSum(out.data(), N);
  return out;
}

/// `reduce` over a matrix's runs: per block of kRowBlock rows, runBody(r) for the block's runs in
/// order (writing per-row results), then rowSum(i, sums) for its rows in order (`reduceHostLanes`
/// with one lane; runs never cross a block boundary, see CsrRowRuns).
template <int N, class RunBody, class RowSum>
std::array<double, N> reduceRuns(const ExecSpace& exec, const SolverComm& comm, const std::string& label,
                                 const CsrMatrix& A, const RunBody& runBody, const RowSum& rowSum) {
  const lid_t* blockStart = A.runs.blockStart.data();
  return reduceHostLanes<N, 1>(
      exec, comm, label, A.nRows,
      [=](lid_t b0, lid_t) {
        const lid_t blk = b0 / kRowBlock;
        for (lid_t r = blockStart[blk]; r < blockStart[blk + 1]; ++r) runBody(r);
      },
      rowSum);
}

/// Whether A's kernels take the run path.
inline bool useRuns(const CsrMatrix& A) { return kHostExec && A.runs.count > 0; }

/// y = alpha M x + beta y (beta = 0: y not read) for a CSR matrix whose values `val` are of type S
/// (rowPtr, colIdx and runs a CsrMatrix's; a float copy of its values shares them): row by row,
/// and on host backends by M's row runs. blas::spmv (S = double) and the distributed AMG's cycle
/// (kernels/DistributedAmg.cpp, S = float or double).
template <class S, class Val, class X, class Y>
void spmvRows(const ExecSpace& exec, const char* label, S alpha, lid_t nRows, const CsrRowRuns& runs,
              const IndexView& rowPtr, const IndexView& colIdx, const Val& val, const X& x, S beta, const Y& y) {
  if (kHostExec && runs.count > 0) {
    const RunViewOf<S> R(runs, rowPtr, val.data());
    const S* xp = x.data();
    S* yp = y.data();
    exec.fence();
    Kokkos::parallel_for(label, hostPolicy(exec, 0, runs.count), [=](lid_t r) {
      forRunRows(R, r, [&](lid_t i, const S* v, const lid_t* off, auto width) {
        const S t = runRowDot(v, xp, i, off, width);
        yp[i] = beta == 0 ? alpha * t : alpha * t + beta * yp[i];
      });
    });
    HostExecSpace().fence();
    return;
  }
  const ConstIndexView rp = rowPtr, ci = colIdx;
  Kokkos::parallel_for(
      label, RangePolicy(exec, 0, nRows), KOKKOS_LAMBDA(lid_t i) {
        S t = 0;
        for (lid_t k = rp(i); k < rp(i + 1); ++k) t += val(k) * x(ci(k));
        y(i) = beta == 0 ? alpha * t : alpha * t + beta * y(i);
      });
}

/// spmvRows over one part of a ghost split (CsrGhostSplit::kInterior or kBoundary): the same
/// value in every row it writes, so the two parts give spmvRows bit for bit.
template <class S, class Val, class X, class Y>
void spmvRowSet(const ExecSpace& exec, const char* label, S alpha, const CsrRowRuns& runs, const IndexView& rowPtr,
                const IndexView& colIdx, const Val& val, const X& x, S beta, const Y& y, const CsrGhostSplit& split,
                int part) {
  if (kHostExec && runs.count > 0) {
    const RunViewOf<S> R(runs, rowPtr, val.data());
    const lid_t* list = split.runs[part].data();
    const S* xp = x.data();
    S* yp = y.data();
    exec.fence();
    Kokkos::parallel_for(
        label, hostPolicy(exec, 0, static_cast<lid_t>(split.runs[part].extent(0))), [=](lid_t k) {
          forRunRows(R, list[k], [&](lid_t i, const S* v, const lid_t* off, auto width) {
            const S t = runRowDot(v, xp, i, off, width);
            yp[i] = beta == 0 ? alpha * t : alpha * t + beta * yp[i];
          });
        });
    HostExecSpace().fence();
    return;
  }
  const ConstIndexView rp = rowPtr, ci = colIdx, list = split.rows[part];
  Kokkos::parallel_for(
      label, RangePolicy(exec, 0, static_cast<lid_t>(list.extent(0))), KOKKOS_LAMBDA(lid_t k) {
        const lid_t i = list(k);
        S t = 0;
        for (lid_t j = rp(i); j < rp(i + 1); ++j) t += val(j) * x(ci(j));
        y(i) = beta == 0 ? alpha * t : alpha * t + beta * y(i);
      });
}

}  // namespace detail

/// \brief y = A x (rows [0, A.nRows); x has A.nCols entries).
void spmv(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& x, const RealView& y);

/// \brief y = alpha A x + beta y. With beta == 0, y is not read (may hold NaN).
void spmv(const ExecSpace& exec, real alpha, const CsrMatrix& A, const ConstRealView& x, real beta, const RealView& y);

/// \brief Fused y = A x and return the global w.y (w = x gives the CG curvature p.Ap).
double spmvDot(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
               const RealView& y, const ConstRealView& w);

/// \brief `comm.updateGhosts(x)` then `spmvDot(A, x, y, w)`, with the exchange overlapped by the
/// product's interior: the exchange begins, the blocks of rows that read no ghost are multiplied
/// and summed, the exchange ends, the other blocks follow. Bitwise `spmvDot`'s y and sum (the
/// block partials are added in block order). Needs A.ghostSplit (kernels/CsrBuild); without it,
/// or when `comm` does not overlap (SolverComm::overlapsGhosts), the two steps one after the other.
double spmvDotOverlapped(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const RealView& x,
                         const RealView& y, const ConstRealView& w);

/// \brief Fused r = b - A x; returns the global r.r.
double residual(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
                const ConstRealView& b, const RealView& r);

/// \brief The two norms the Krylov stopping rules use, as global sums: r.r and |r|_1 = sum |r_i|.
struct ResidualNorms {
  double rr = 0.0;
  double l1 = 0.0;
};

/// \brief Fused r = b - A x; returns the global r.r and |r|_1 (r.r bitwise equal to `residual`'s).
ResidualNorms residualNorms(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
                            const ConstRealView& b, const RealView& r);

/// \brief Y = A X for the three columns of an n x 3 multi-vector, reading the matrix once.
/// Column c of Y is bitwise the single-vector `spmv` of column c.
void spmv(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& x, const Real3View& y);

/// \brief Fused R = B - A X for three columns (one matrix read); per column r.r and |r|_1, each
/// bitwise equal to the single-vector `residualNorms` of that column.
std::array<ResidualNorms, 3> residualNorms(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A,
                                           const ConstReal3View& x, const ConstReal3View& b, const Real3View& r);

/// \brief Global x.y over the first n entries.
double dot(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x, const ConstRealView& y);

/// \brief Global sqrt(x.x) over the first n entries.
double norm2(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x);

/// \brief Global max |x_i| over the first n entries (+inf if any entry is NaN).
double normInf(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x);

/// \brief Global sum of the first n entries.
double sum(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x);

/// \brief y += alpha x over the first n entries.
void axpy(const ExecSpace& exec, lid_t n, real alpha, const ConstRealView& x, const RealView& y);

/// \brief y = alpha x + beta y over the first n entries. With beta == 0, y is not read.
void axpby(const ExecSpace& exec, lid_t n, real alpha, const ConstRealView& x, real beta, const RealView& y);

/// \brief x += c over the first n entries (used to remove a mean).
void shift(const ExecSpace& exec, lid_t n, real c, const RealView& x);

/// \brief x = value over the first n entries.
void fill(const ExecSpace& exec, lid_t n, real value, const RealView& x);

/// \brief Global mean of x: sum(x) / (global n). Used to project out a constant null space.
double mean(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x);

}  // namespace blas
}  // namespace mfsi
