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
#include "kernels/CsrMatrix.hpp"

#include <array>
#include <string>

namespace mfsi {

/// \brief The rank-decomposition hooks of the linear algebra. One rank: sums are local and there
/// are no ghosts. An MPI version replaces the bodies by `MPI_Allreduce` (a single call for all
/// values of a fused reduction) and a halo exchange; no solver code changes.
class SolverComm {
 public:
  /// \brief Sum `n` per-rank partial sums over all ranks, in place.
  void globalSum(double* values, int n) const {
    (void)values;
    (void)n;
  }
  /// \brief Sum one per-rank partial sum over all ranks.
  double globalSum(double local) const {
    globalSum(&local, 1);
    return local;
  }
  /// \brief Maximum of a per-rank value over all ranks.
  double globalMax(double local) const { return local; }
  /// \brief Refresh ghost entries [nRows, nCols) of `x` before it is multiplied by a matrix.
  void updateGhosts(const ExecSpace& exec, const RealView& x) const {
    (void)exec;
    (void)x;
  }
  /// \brief Same for the rows [nRows, nCols) of an n x 3 multi-vector (one exchange for all three).
  void updateGhosts(const ExecSpace& exec, const Real3View& x) const {
    (void)exec;
    (void)x;
  }
};

namespace blas {

/// \brief Rows per block of a deterministic reduction (see the file comment).
inline constexpr lid_t kReductionBlock = 256;

/// \brief N running sums carried through a fused reduction body.
template <int N>
struct Sums {
  double v[N];
  KOKKOS_INLINE_FUNCTION double& operator[](int k) { return v[k]; }
  KOKKOS_INLINE_FUNCTION const double& operator[](int k) const { return v[k]; }
};

/// \brief Deterministic fused reduction: calls `body(i, sums)` for i in [0, n) (a device
/// lambda/functor adding its contributions to `Sums<N>& sums`), returns the N global sums.
/// Blocks of `kReductionBlock` rows are summed in order by one thread each; block sums are added
/// in block order on the host, then `comm.globalSum` combines the ranks. Fences `exec`.
template <int N, class Body>
std::array<double, N> reduce(const ExecSpace& exec, const SolverComm& comm, const std::string& label, lid_t n,
                             const Body& body) {
  const lid_t bs = kReductionBlock;
  const lid_t nBlocks = (n + bs - 1) / bs;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> partial(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, label + "::partials"), nBlocks, N);
  Kokkos::parallel_for(
      label, RangePolicy(exec, 0, nBlocks), KOKKOS_LAMBDA(lid_t blk) {
        Sums<N> s;
        for (int k = 0; k < N; ++k) s[k] = 0.0;
        const lid_t begin = blk * bs;
        const lid_t end = begin + bs < n ? begin + bs : n;
        for (lid_t i = begin; i < end; ++i) body(i, s);
        for (int k = 0; k < N; ++k) partial(blk, k) = s[k];
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

/// \brief y = A x (rows [0, A.nRows); x has A.nCols entries).
void spmv(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& x, const RealView& y);

/// \brief y = alpha A x + beta y. With beta == 0, y is not read (may hold NaN).
void spmv(const ExecSpace& exec, real alpha, const CsrMatrix& A, const ConstRealView& x, real beta, const RealView& y);

/// \brief Fused y = A x and return the global w.y (w = x gives the CG curvature p.Ap).
double spmvDot(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
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
