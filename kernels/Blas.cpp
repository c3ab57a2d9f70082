#include "kernels/Blas.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace mfsi {

SolverComm::SolverComm(MPI_Comm comm, const Halo* halo) : comm_(comm), halo_(halo) {
  if (comm_ != MPI_COMM_NULL) MPI_Comm_size(comm_, &size_);
}

namespace {
std::int64_t gReductions = 0;
double gReductionSeconds = 0;
}  // namespace

std::int64_t SolverComm::reductions() { return gReductions; }
double SolverComm::reductionSeconds() { return gReductionSeconds; }

void SolverComm::gatherSum(double* values, int n) const {
  ++gReductions;
  // Every rank's partials, added in rank order: the same bits on every rank, every run.
  std::vector<double> all(static_cast<std::size_t>(n) * size_);
  const double t0 = MPI_Wtime();
  MPI_Allgather(values, n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, comm_);
  gReductionSeconds += MPI_Wtime() - t0;
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int r = 0; r < size_; ++r) s += all[static_cast<std::size_t>(r) * n + i];
    values[i] = s;
  }
}

double SolverComm::reduceMax(double local) const {
  ++gReductions;
  double global = local;
  const double t0 = MPI_Wtime();
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, comm_);
  gReductionSeconds += MPI_Wtime() - t0;
  return global;
}

}  // namespace mfsi

namespace mfsi::blas {

void spmv(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& x, const RealView& y) {
  spmv(exec, 1.0, A, x, 0.0, y);
}

void spmv(const ExecSpace& exec, real alpha, const CsrMatrix& A, const ConstRealView& x, real beta, const RealView& y) {
  detail::spmvRows(exec, "mfsi::kernels::blas::spmv", alpha, A.nRows, A.runs, A.rowPtr, A.colIdx,
                   ConstRealView(A.values), x, beta, y);
}

double spmvDot(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
               const RealView& y, const ConstRealView& w) {
  if (detail::useRuns(A)) {
    const detail::RunView R(A);
    const double* xp = x.data();
    const double* wp = w.data();
    double* yp = y.data();
    return detail::reduceRuns<1>(
        exec, comm, "mfsi::kernels::blas::spmvDot", A,
        [=](lid_t r) {
          detail::forRunRows(R, r, [&](lid_t i, const double* v, const lid_t* off, auto width) {
            yp[i] = detail::runRowDot(v, xp, i, off, width);
          });
        },
        [=](lid_t i, Sums<1>& s) { s[0] += wp[i] * yp[i]; })[0];
  }
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  return reduce<1>(
      exec, comm, "mfsi::kernels::blas::spmvDot", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<1> & s) {
        double ax = 0.0;
        for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) ax += val(k) * x(colIdx(k));
        y(i) = ax;
        s[0] += w(i) * ax;
      })[0];
}

namespace detail {

/// The blocks of one part of A's ghost split, each as spmvDot sums it (its rows' products in row
/// order): y on their rows, each block's sum in partial(block).
void spmvDotBlocks(const ExecSpace& exec, const CsrMatrix& A, int part, const ConstRealView& x, const RealView& y,
                   const ConstRealView& w, const RealView& partial) {
  const CsrGhostSplit& split = A.ghostSplit;
  const lid_t n = A.nRows, bs = kReductionBlock;
  const lid_t count = static_cast<lid_t>(split.blocks[part].extent(0));
  if (useRuns(A)) {
    const RunView R(A);
    const lid_t* list = split.blocks[part].data();
    const lid_t* blockStart = A.runs.blockStart.data();
    const double* xp = x.data();
    const double* wp = w.data();
    double* yp = y.data();
    double* sums = partial.data();
    exec.fence();
    Kokkos::parallel_for("mfsi::kernels::blas::spmvDotOverlapped", hostPolicy(exec, 0, count), [=](lid_t k) {
      const lid_t blk = list[k];
      for (lid_t r = blockStart[blk]; r < blockStart[blk + 1]; ++r)
        forRunRows(R, r, [&](lid_t i, const double* v, const lid_t* off, auto width) {
          yp[i] = runRowDot(v, xp, i, off, width);
        });
      const lid_t end = (blk + 1) * bs < n ? (blk + 1) * bs : n;
      double s = 0.0;
      for (lid_t i = blk * bs; i < end; ++i) s += wp[i] * yp[i];
      sums[blk] = s;
    });
    HostExecSpace().fence();
    return;
  }
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx, list = split.blocks[part];
  const ConstRealView val = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::blas::spmvDotOverlapped", RangePolicy(exec, 0, count), KOKKOS_LAMBDA(lid_t k) {
        const lid_t blk = list(k);
        const lid_t end = (blk + 1) * bs < n ? (blk + 1) * bs : n;
        double s = 0.0;
        for (lid_t i = blk * bs; i < end; ++i) {
          double ax = 0.0;
          for (lid_t j = rowPtr(i); j < rowPtr(i + 1); ++j) ax += val(j) * x(colIdx(j));
          y(i) = ax;
          s += w(i) * ax;
        }
        partial(blk) = s;
      });
}

}  // namespace detail

double spmvDotOverlapped(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const RealView& x,
                         const RealView& y, const ConstRealView& w) {
  if (!comm.overlapsGhosts() || A.ghostSplit.empty()) {
    comm.updateGhosts(exec, x);
    return spmvDot(exec, comm, A, x, y, w);
  }
  const lid_t nBlocks = (A.nRows + kReductionBlock - 1) / kReductionBlock;
  const RealView partial(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::kernels::blas::spmvDotOverlapped::partials"), nBlocks);
  comm.beginGhosts(exec, x);
  detail::spmvDotBlocks(exec, A, CsrGhostSplit::kInterior, x, y, w, partial);
  comm.endGhosts(exec, x);
  detail::spmvDotBlocks(exec, A, CsrGhostSplit::kBoundary, x, y, w, partial);
  auto host = Kokkos::create_mirror_view(partial);
  Kokkos::deep_copy(exec, host, partial);
  exec.fence();
  double out = 0.0;
  for (lid_t b = 0; b < nBlocks; ++b) out += host(b);
  comm.globalSum(&out, 1);
  return out;
}

double residual(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
                const ConstRealView& b, const RealView& r) {
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  return reduce<1>(
      exec, comm, "mfsi::kernels::blas::residual", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<1> & s) {
        double ri = b(i);
        for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) ri -= val(k) * x(colIdx(k));
        r(i) = ri;
        s[0] += ri * ri;
      })[0];
}

ResidualNorms residualNorms(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A, const ConstRealView& x,
                            const ConstRealView& b, const RealView& r) {
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  const auto s = reduce<2>(
      exec, comm, "mfsi::kernels::blas::residualNorms", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
        double ri = b(i);
        for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) ri -= val(k) * x(colIdx(k));
        r(i) = ri;
        acc[0] += ri * ri;
        acc[1] += kmath::fabs(ri);
      });
  return {s[0], s[1]};
}

void spmv(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& x, const Real3View& y) {
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::blas::spmv3", RangePolicy(exec, 0, A.nRows), KOKKOS_LAMBDA(lid_t i) {
        double s0 = 0.0, s1 = 0.0, s2 = 0.0;
        for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) {
          const double a = val(k);
          const lid_t j = colIdx(k);
          s0 += a * x(j, 0);
          s1 += a * x(j, 1);
          s2 += a * x(j, 2);
        }
        y(i, 0) = s0;
        y(i, 1) = s1;
        y(i, 2) = s2;
      });
}

std::array<ResidualNorms, 3> residualNorms(const ExecSpace& exec, const SolverComm& comm, const CsrMatrix& A,
                                           const ConstReal3View& x, const ConstReal3View& b, const Real3View& r) {
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  // Sums: r.r of the three columns, then their |r|_1.
  const auto s = reduce<6>(
      exec, comm, "mfsi::kernels::blas::residualNorms3", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<6> & acc) {
        double r0 = b(i, 0), r1 = b(i, 1), r2 = b(i, 2);
        for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) {
          const double a = val(k);
          const lid_t j = colIdx(k);
          r0 -= a * x(j, 0);
          r1 -= a * x(j, 1);
          r2 -= a * x(j, 2);
        }
        r(i, 0) = r0;
        r(i, 1) = r1;
        r(i, 2) = r2;
        acc[0] += r0 * r0;
        acc[1] += r1 * r1;
        acc[2] += r2 * r2;
        acc[3] += kmath::fabs(r0);
        acc[4] += kmath::fabs(r1);
        acc[5] += kmath::fabs(r2);
      });
  return {ResidualNorms{s[0], s[3]}, ResidualNorms{s[1], s[4]}, ResidualNorms{s[2], s[5]}};
}

double dot(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x, const ConstRealView& y) {
  return reduce<1>(
      exec, comm, "mfsi::kernels::blas::dot", n, KOKKOS_LAMBDA(lid_t i, Sums<1> & s) { s[0] += x(i) * y(i); })[0];
}

double norm2(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x) {
  const double xx = reduce<1>(
      exec, comm, "mfsi::kernels::blas::norm2", n, KOKKOS_LAMBDA(lid_t i, Sums<1> & s) { s[0] += x(i) * x(i); })[0];
  return std::sqrt(xx);
}

double normInf(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x) {
  // max is order-independent, so a plain Kokkos reduction is already deterministic. NaN compares
  // false with everything and would be dropped by the max; map it to +inf so it is reported.
  double m = 0.0;
  const double inf = std::numeric_limits<double>::infinity();
  Kokkos::parallel_reduce(
      "mfsi::kernels::blas::normInf", RangePolicy(exec, 0, n),
      KOKKOS_LAMBDA(lid_t i, double& acc) {
        double a = kmath::fabs(x(i));
        if (a != a) a = inf;
        if (a > acc) acc = a;
      },
      Kokkos::Max<double>(m));
  return comm.globalMax(m < 0.0 ? 0.0 : m);  // empty range: identity of Max is -inf
}

double sum(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x) {
  return reduce<1>(
      exec, comm, "mfsi::kernels::blas::sum", n, KOKKOS_LAMBDA(lid_t i, Sums<1> & s) { s[0] += x(i); })[0];
}

double mean(const ExecSpace& exec, const SolverComm& comm, lid_t n, const ConstRealView& x) {
  const double total = comm.globalSum(static_cast<double>(n));
  return total > 0 ? sum(exec, comm, n, x) / total : 0.0;
}

void axpy(const ExecSpace& exec, lid_t n, real alpha, const ConstRealView& x, const RealView& y) {
  Kokkos::parallel_for(
      "mfsi::kernels::blas::axpy", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { y(i) += alpha * x(i); });
}

void axpby(const ExecSpace& exec, lid_t n, real alpha, const ConstRealView& x, real beta, const RealView& y) {
  Kokkos::parallel_for(
      "mfsi::kernels::blas::axpby", RangePolicy(exec, 0, n),
      KOKKOS_LAMBDA(lid_t i) { y(i) = beta == 0.0 ? alpha * x(i) : alpha * x(i) + beta * y(i); });
}

void shift(const ExecSpace& exec, lid_t n, real c, const RealView& x) {
  Kokkos::parallel_for(
      "mfsi::kernels::blas::shift", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { x(i) += c; });
}

void fill(const ExecSpace& exec, lid_t n, real value, const RealView& x) {
  Kokkos::parallel_for(
      "mfsi::kernels::blas::fill", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { x(i) = value; });
}

}  // namespace mfsi::blas
