#include "kernels/LatticeMatrix.hpp"

#include "core/Error.hpp"
#include "kernels/Amg.hpp"

#include <string>

namespace mfsi {

namespace {

/// Row i of A x from the lattice arrays, for any row (branches on the neighbours that leave
/// [0, n)). sz = n on a one-cell-thick lattice: its z terms are never taken and uz never read.
/// Terms in column order, as the CSR row kernels sum them.
KOKKOS_INLINE_FUNCTION double latticeRow(lid_t i, lid_t n, lid_t sy, lid_t sz, const double* d, const double* ux,
                                         const double* uy, const double* uz, const double* x) {
  double s = 0.0;
  if (i >= sz) s += uz[i - sz] * x[i - sz];
  if (i >= sy) s += uy[i - sy] * x[i - sy];
  if (i >= 1) s += ux[i - 1] * x[i - 1];
  s += d[i] * x[i];
  if (i + 1 < n) s += ux[i] * x[i + 1];
  if (i + sy < n) s += uy[i] * x[i + sy];
  if (i + sz < n) s += uz[i] * x[i + sz];
  return s;
}

/// Row sum of row i (the couplings in column order, as latticeRow).
KOKKOS_INLINE_FUNCTION double latticeRowSum(lid_t i, lid_t n, lid_t sy, lid_t sz, const double* d, const double* ux,
                                            const double* uy, const double* uz) {
  double s = 0.0;
  if (i >= sz) s += uz[i - sz];
  if (i >= sy) s += uy[i - sy];
  if (i >= 1) s += ux[i - 1];
  s += d[i];
  if (i + 1 < n) s += ux[i];
  if (i + sy < n) s += uy[i];
  if (i + sz < n) s += uz[i];
  return s;
}

/// Host pointers of the lattice arrays and the strides (sz = n one cell thick).
struct LatticePtrs {
  lid_t n = 0, sy = 0, sz = 0;
  bool is3D = false;
  const double *d = nullptr, *ux = nullptr, *uy = nullptr, *uz = nullptr;
  LatticePtrs(lid_t nRows, lid_t nx, lid_t ny, lid_t nz, const RealView& dv, const RealView& uxv, const RealView& uyv,
              const RealView& uzv)
      : n(nRows),
        sy(nx),
        sz(nz > 1 ? nx * ny : nRows),
        is3D(nz > 1),
        d(dv.data()),
        ux(uxv.data()),
        uy(uyv.data()),
        uz(uzv.data()) {}
};

/// y = A x on rows [i0, i1) (host). Rows whose every neighbour lies in [0, n) - all but the first
/// and last plane (row of a one-cell-thick lattice) - take a branch-free loop with contiguous
/// loads of the four arrays and of x at seven fixed offsets, which the compiler vectorises.
inline void latticeRowsHost(const LatticePtrs& P, lid_t i0, lid_t i1, const double* x, double* y) {
  const lid_t s = P.is3D ? P.sz : P.sy;  // widest stride
  const lid_t lo = i0 > s ? i0 : s;
  const lid_t hi = i1 < P.n - s ? i1 : P.n - s;
  const double *d = P.d, *ux = P.ux, *uy = P.uy, *uz = P.uz;
  const lid_t sy = P.sy, sz = P.sz;
  if (lo >= hi) {
    for (lid_t i = i0; i < i1; ++i) y[i] = latticeRow(i, P.n, sy, sz, d, ux, uy, uz, x);
    return;
  }
  for (lid_t i = i0; i < lo; ++i) y[i] = latticeRow(i, P.n, sy, sz, d, ux, uy, uz, x);
  if (P.is3D) {
    MFSI_IVDEP
    for (lid_t i = lo; i < hi; ++i) {
      double t = 0.0;
      t += uz[i - sz] * x[i - sz];
      t += uy[i - sy] * x[i - sy];
      t += ux[i - 1] * x[i - 1];
      t += d[i] * x[i];
      t += ux[i] * x[i + 1];
      t += uy[i] * x[i + sy];
      t += uz[i] * x[i + sz];
      y[i] = t;
    }
  } else {
    MFSI_IVDEP
    for (lid_t i = lo; i < hi; ++i) {
      double t = 0.0;
      t += uy[i - sy] * x[i - sy];
      t += ux[i - 1] * x[i - 1];
      t += d[i] * x[i];
      t += ux[i] * x[i + 1];
      t += uy[i] * x[i + sy];
      y[i] = t;
    }
  }
  for (lid_t i = hi; i < i1; ++i) y[i] = latticeRow(i, P.n, sy, sz, d, ux, uy, uz, x);
}

}  // namespace

void SymmetricLatticeMatrix::clear() { *this = SymmetricLatticeMatrix(); }

bool SymmetricLatticeMatrix::holdsSparsityOf(const CsrMatrix& A) const {
  return rowPtr_.data() != nullptr && A.nRows == nRows_ && A.nnz() == nnz_ && A.rowPtr.data() == rowPtr_.data() &&
         A.colIdx.data() == colIdx_.data();
}

bool SymmetricLatticeMatrix::matches(const CsrMatrix& A) const {
  return valid_ && holdsSparsityOf(A) && A.values.data() == values_.data();
}

bool SymmetricLatticeMatrix::prepare(const CsrMatrix& A) {
  if (!holdsSparsityOf(A)) {
    // New sparsity: detect its lattice once (host copy of the sparsity: a set-up cost).
    clear();
    rowPtr_ = A.rowPtr;
    colIdx_ = A.colIdx;
    nRows_ = A.nRows;
    nnz_ = A.nnz();
    const AmgLattice g = A.nRows > 0 ? detectLattice(A) : AmgLattice{};
    lattice_ = g.valid();
    if (lattice_) {
      nx_ = g.nx;
      ny_ = g.ny;
      nz_ = g.nz;
      const std::string l = "mfsi::kernels::lattice::";
      const auto alloc = [&](const char* what) {
        return RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, l + what), nRows_);
      };
      diag_ = alloc("diag");
      ux_ = alloc("ux");
      uy_ = alloc("uy");
      if (nz_ > 1) uz_ = alloc("uz");
    }
  }
  values_ = A.values;
  valid_ = false;
  assembled_ = false;
  return lattice_;
}

void SymmetricLatticeMatrix::markAssembled(const CsrMatrix& A) {
  MFSI_CHECK(lattice_ && holdsSparsityOf(A),
             "SymmetricLatticeMatrix::markAssembled: prepare() was not called for this matrix's lattice sparsity");
  values_ = A.values;
  valid_ = true;
  assembled_ = true;
}

void SymmetricLatticeMatrix::writeCsr(const ExecSpace& exec, const CsrMatrix& A) const {
  MFSI_CHECK(matches(A), "SymmetricLatticeMatrix::writeCsr: the lattice does not hold this matrix");
  // One lattice line per work item, as the copy in `update`: row i holds, in column order,
  // [-sz if z > 0] [-sy if y > 0] [-1 if x > 0] diag [+1] [+sy] [+sz]; a lower coupling is the
  // upper one of the row it couples to.
  const lid_t nx = nx_, ny = ny_, nz = nz_, sy = nx_, sz = nx_ * ny_;
  const ConstIndexView rowPtr = A.rowPtr;
  const RealView val = A.values;
  const ConstRealView d = diag_, ux = ux_, uy = uy_, uz = uz_;
  Kokkos::parallel_for(
      "mfsi::kernels::lattice::writeCsr", RangePolicy(exec, 0, ny * nz), KOKKOS_LAMBDA(lid_t line) {
        const lid_t z = line / ny, y = line - z * ny;
        const lid_t base = line * nx;
        for (lid_t xx = 0; xx < nx; ++xx) {
          const lid_t i = base + xx;
          lid_t k = rowPtr(i);
          if (z > 0) val(k++) = uz(i - sz);
          if (y > 0) val(k++) = uy(i - sy);
          if (xx > 0) val(k++) = ux(i - 1);
          val(k++) = d(i);
          if (xx + 1 < nx) val(k++) = ux(i);
          if (y + 1 < ny) val(k++) = uy(i);
          if (z + 1 < nz) val(k) = uz(i);
        }
      });
}

bool SymmetricLatticeMatrix::update(const ExecSpace& exec, const CsrMatrix& A) {
  if (!prepare(A)) return false;

  // Copy the diagonal and upper couplings, one lattice line (fixed y, z) per work item so that
  // the CSR positions follow from the line's coordinates without divisions: row i at (x, y, z)
  // holds, in column order, [-sz if z > 0] [-sy if y > 0] [-1 if x > 0] diag [+1] [+sy] [+sz].
  // a_ij == a_ji is checked exactly for every upper coupling (NaN counts as asymmetric).
  const lid_t nx = nx_, ny = ny_, nz = nz_, sy = nx_, sz = nx_ * ny_;
  const ConstIndexView rowPtr = A.rowPtr;
  const ConstRealView val = A.values;
  const RealView d = diag_, ux = ux_, uy = uy_, uz = uz_;
  lid_t asymmetric = 0;
  Kokkos::parallel_reduce(
      "mfsi::kernels::lattice::copy", RangePolicy(exec, 0, ny * nz),
      KOKKOS_LAMBDA(lid_t line, lid_t & bad) {
        const lid_t z = line / ny, y = line - z * ny;
        const lid_t zlo = z > 0 ? 1 : 0, ylo = y > 0 ? 1 : 0;
        const bool yhi = y + 1 < ny, zhi = z + 1 < nz;
        const lid_t base = line * nx;
        for (lid_t xx = 0; xx < nx; ++xx) {
          const lid_t i = base + xx;
          lid_t k = rowPtr(i) + zlo + ylo + (xx > 0 ? 1 : 0);
          d(i) = val(k++);
          double a = 0.0;
          if (xx + 1 < nx) {
            a = val(k++);
            if (!(a == val(rowPtr(i + 1) + zlo + ylo))) ++bad;
          }
          ux(i) = a;
          a = 0.0;
          if (yhi) {
            a = val(k++);
            if (!(a == val(rowPtr(i + sy) + zlo))) ++bad;
          }
          uy(i) = a;
          if (nz > 1) {
            a = 0.0;
            if (zhi) {
              a = val(k);
              if (!(a == val(rowPtr(i + sz)))) ++bad;
            }
            uz(i) = a;
          }
        }
      },
      asymmetric);
  valid_ = asymmetric == 0;
  return valid_;
}

double SymmetricLatticeMatrix::spmvDot(const ExecSpace& exec, const SolverComm& comm, const ConstRealView& x,
                                       const RealView& y, const ConstRealView& w) const {
  const LatticePtrs P(nRows_, nx_, ny_, nz_, diag_, ux_, uy_, uz_);
  const lid_t n = P.n, sy = P.sy, sz = P.sz;
  if constexpr (kHostExec) {
    const double* xp = x.data();
    const double* wp = w.data();
    double* yp = y.data();
    return blas::detail::reduceHostLanes<1, blas::kReductionLanes>(
        exec, comm, "mfsi::kernels::lattice::spmvDot", n,
        [=](lid_t i0, lid_t i1) { latticeRowsHost(P, i0, i1, xp, yp); },
        [=](lid_t i, blas::Sums<1>& s) { s[0] += wp[i] * yp[i]; })[0];
  } else {
    const double *d = P.d, *ux = P.ux, *uy = P.uy, *uz = P.uz;
    const double* xp = x.data();
    const RealView yv = y;
    const ConstRealView wv = w;
    return blas::reduceLanes<1>(
        exec, comm, "mfsi::kernels::lattice::spmvDot", n, KOKKOS_LAMBDA(lid_t i, blas::Sums<1> & s) {
          const double yi = latticeRow(i, n, sy, sz, d, ux, uy, uz, xp);
          yv(i) = yi;
          s[0] += wv(i) * yi;
        })[0];
  }
}

void SymmetricLatticeMatrix::spmv(const ExecSpace& exec, const ConstRealView& x, const RealView& y) const {
  const LatticePtrs P(nRows_, nx_, ny_, nz_, diag_, ux_, uy_, uz_);
  const lid_t n = P.n, sy = P.sy, sz = P.sz;
  const double *d = P.d, *ux = P.ux, *uy = P.uy, *uz = P.uz;
  const double* xp = x.data();
  double* yp = y.data();
  if constexpr (kHostExec) {
    const lid_t bs = kRowBlock, nBlocks = (n + bs - 1) / bs;
    exec.fence();
    Kokkos::parallel_for("mfsi::kernels::lattice::spmv", blas::detail::hostPolicy(exec, 0, nBlocks),
                         [=](lid_t b) { latticeRowsHost(P, b * bs, (b + 1) * bs < n ? (b + 1) * bs : n, xp, yp); });
    HostExecSpace().fence();
  } else {
    Kokkos::parallel_for(
        "mfsi::kernels::lattice::spmv", RangePolicy(exec, 0, n),
        KOKKOS_LAMBDA(lid_t i) { yp[i] = latticeRow(i, n, sy, sz, d, ux, uy, uz, xp); });
  }
}

std::array<double, 4> SymmetricLatticeMatrix::scaledResidual(const ExecSpace& exec, const SolverComm& comm,
                                                             const ConstRealView& x, const ConstRealView& b,
                                                             double xbar, const RealView& r) const {
  const LatticePtrs P(nRows_, nx_, ny_, nz_, diag_, ux_, uy_, uz_);
  const lid_t n = P.n, sy = P.sy, sz = P.sz;
  const double *d = P.d, *ux = P.ux, *uy = P.uy, *uz = P.uz;
  const double* xp = x.data();
  return blas::reduce<4>(
      exec, comm, "mfsi::kernels::lattice::scaledResidual", n, KOKKOS_LAMBDA(lid_t i, blas::Sums<4> & acc) {
        const double ax = latticeRow(i, n, sy, sz, d, ux, uy, uz, xp);
        const double rs = latticeRowSum(i, n, sy, sz, d, ux, uy, uz);
        r(i) = blas::scaledResidualTerms(b(i), ax, rs, xbar, acc);
      });
}

}  // namespace mfsi
