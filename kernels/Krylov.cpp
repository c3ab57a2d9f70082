#include "kernels/Krylov.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi {

const char* toString(KrylovStatus status) {
  switch (status) {
    case KrylovStatus::Converged:
      return "converged";
    case KrylovStatus::MaxIterations:
      return "max-iterations";
    case KrylovStatus::Breakdown:
      return "breakdown";
    case KrylovStatus::NotFinite:
      return "not-finite";
  }
  return "?";
}

std::unique_ptr<KrylovSolver> makeKrylovSolver(KrylovMethod method, const KrylovOptions& options,
                                               const SolverComm& comm) {
  switch (method) {
    case KrylovMethod::CG:
      return std::make_unique<ConjugateGradient>(options, comm);
    case KrylovMethod::BiCGStab:
      return std::make_unique<BiCGStab>(options, comm);
  }
  MFSI_CHECK(false, "makeKrylovSolver: unknown method");
  return nullptr;
}

namespace {

using blas::reduce;
using blas::Sums;

void ensureSize(RealView& v, lid_t n, const char* label) {
  if (v.extent(0) != static_cast<std::size_t>(n)) {
    v = RealView(std::string(label), n);  // zero-initialised: ghost entries start defined
  }
}

void ensureSize(Real3View& v, lid_t n, const char* label) {
  if (v.extent(0) != static_cast<std::size_t>(n)) v = Real3View(std::string(label), n);
}

bool finite(double v) { return std::isfinite(v); }

/// The stopping test of one right-hand side: 2-norm target or 1-norm target (see KrylovOptions).
struct Stop {
  double target = 0.0;
  double l1Target = 0.0;
  bool met(double rr, double l1) const { return std::sqrt(rr) <= target || l1 <= l1Target; }
};

/// Shared set-up of both single-vector methods: r = b - A x (or the caller's r0), projected when
/// asked, its norms, and the stopping test.
struct Start {
  double rr = 0.0;
  double l1 = 0.0;
  Stop stop;
};

Start start(const ExecSpace& exec, const SolverComm& comm, const KrylovOptions& opt, const CsrMatrix& A,
            const ConstRealView& b, const RealView& x, const RealView& r, const InitialResidual* r0, double nGlobal,
            KrylovResult& res) {
  const bool project = opt.nullSpace == NullSpace::Constant;
  Start s;
  if (r0 != nullptr) {
    s.rr = r0->rr;
    s.l1 = r0->l1;
  } else {
    comm.updateGhosts(exec, x);
    const auto norms = blas::residualNorms(exec, comm, A, x, b, r);
    s.rr = norms.rr;
    s.l1 = norms.l1;
  }
  if (project) {
    blas::shift(exec, A.nRows, -blas::mean(exec, comm, A.nRows, r), r);
    const auto nr = reduce<2>(
        exec, comm, "mfsi::kernels::krylov::projectedNorms", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          acc[0] += r(i) * r(i);
          acc[1] += kmath::fabs(r(i));
        });
    s.rr = nr[0];
    s.l1 = nr[1];
  }
  res.initialResidual = res.finalResidual = std::sqrt(s.rr);
  res.initialResidualL1 = res.finalResidualL1 = s.l1;
  double ref = res.initialResidual;
  if (opt.relativeTo == ResidualReference::RightHandSide) {
    // ||b|| (of its consistent part when projecting: sum (b - mean)^2 = b.b - (sum b)^2 / n).
    const auto bb = reduce<2>(
        exec, comm, "mfsi::kernels::krylov::rhsNorm", A.nRows, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          acc[0] += b(i) * b(i);
          acc[1] += b(i);
        });
    ref = std::sqrt(std::max(0.0, project ? bb[0] - bb[1] * bb[1] / nGlobal : bb[0]));
  }
  s.stop.target = std::max(opt.absTol, opt.relTol * ref);
  s.stop.l1Target = opt.l1AbsTol;
  return s;
}

/// Project z onto zero mean (constant null space).
void projectMean(const ExecSpace& exec, const SolverComm& comm, lid_t n, const RealView& z) {
  blas::shift(exec, n, -blas::mean(exec, comm, n, z), z);
}

/// The residual view a solve works in: the caller's r0, or the solver's own work vector.
RealView workResidual(const InitialResidual* r0, RealView& own, lid_t n, const char* label) {
  if (r0 == nullptr) {
    ensureSize(own, n, label);
    return own;
  }
  MFSI_CHECK(r0->r.extent(0) >= static_cast<std::size_t>(n), "Krylov solver: the given initial residual has "
                                                                 << r0->r.extent(0) << " entries, the matrix " << n
                                                                 << " rows");
  return r0->r;
}

/// Row i of A M^{-1} X for the three columns of X, M = diag(1 / inv): the Jacobi scaling is formed
/// inside the gather, so A and inv are read once for all columns (BiCGStab3's two products). Each
/// term is (a_ij inv_j) x_jc: one product of the scaled coefficient serves the three columns.
KOKKOS_INLINE_FUNCTION void jacobiRow3(const ConstIndexView& rowPtr, const ConstIndexView& colIdx,
                                       const ConstRealView& val, const ConstRealView& inv, const Real3View& x,
                                       lid_t i, double out[3]) {
  out[0] = out[1] = out[2] = 0.0;
  for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) {
    const lid_t j = colIdx(k);
    const double a = val(k) * inv(j);
    out[0] += a * x(j, 0);
    out[1] += a * x(j, 1);
    out[2] += a * x(j, 2);
  }
}

/// jacobiRow3 for the rows of run `run` (host backends, see blas::detail::forRunRows): y = A (inv .* x)
/// for the columns c of the row-major n x 3 arrays x and y whose bit (1 << c) is set in Mask, each
/// sum in jacobiRow3's order; the other columns of y are not written. Once a column has converged
/// (cavity 64^3: the second iteration's products are for one or two columns) the products skip
/// its gathers and arithmetic.
template <int Mask>
inline void jacobiRun3(const blas::detail::RunView& R, lid_t run, const double* inv, const double* x, double* y) {
  static_assert(!kHostExec || std::is_same<Real3View::array_layout, Kokkos::LayoutRight>::value,
                "host n x 3 views are row-major");
  blas::detail::forRunRows(R, run, [&](lid_t i, const double* v, const lid_t* off, auto width) {
    [[maybe_unused]] double s0 = 0.0, s1 = 0.0, s2 = 0.0;  // the columns outside Mask stay unused
    for (int k = 0; k < width; ++k) {
      const lid_t j = i + off[k];
      const double a = v[k] * inv[j];
      if constexpr ((Mask & 1) != 0) s0 += a * x[3 * j];
      if constexpr ((Mask & 2) != 0) s1 += a * x[3 * j + 1];
      if constexpr ((Mask & 4) != 0) s2 += a * x[3 * j + 2];
    }
    if constexpr ((Mask & 1) != 0) y[3 * i] = s0;
    if constexpr ((Mask & 2) != 0) y[3 * i + 1] = s1;
    if constexpr ((Mask & 4) != 0) y[3 * i + 2] = s2;
  });
}

/// jacobiRun3 for the columns set in `mask` (1..7).
inline void jacobiRun3(int mask, const blas::detail::RunView& R, lid_t run, const double* inv, const double* x,
                       double* y) {
  using Run = void (*)(const blas::detail::RunView&, lid_t, const double*, const double*, double*);
  static constexpr Run kByMask[8] = {nullptr,       jacobiRun3<1>, jacobiRun3<2>, jacobiRun3<3>,
                                     jacobiRun3<4>, jacobiRun3<5>, jacobiRun3<6>, jacobiRun3<7>};
  kByMask[mask](R, run, inv, x, y);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Conjugate gradients. Per iteration: one SpMV fused with p.Ap, one update of x and r fused with
// {r.r, |r|_1} (the stopping test, before the preconditioner is applied, so the last iteration
// costs no apply), one preconditioner apply, one reduction {r.z, sum z, sum r} and the direction
// update. With a constant null space, z is projected inside the direction update (p = z - mean(z)
// + beta p) and r.z corrected accordingly, so projection costs no extra pass.
// ---------------------------------------------------------------------------------------------
KrylovResult ConjugateGradient::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                      const RealView& x, Preconditioner& M) {
  return run(exec, A, b, x, M, nullptr);
}

KrylovResult ConjugateGradient::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                      const RealView& x, Preconditioner& M, const InitialResidual& r0) {
  return run(exec, A, b, x, M, &r0);
}

void ConjugateGradient::matrixChanged(const ExecSpace& exec, const CsrMatrix& A) { lattice_.update(exec, A); }

KrylovResult ConjugateGradient::run(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                    const RealView& x, Preconditioner& M, const InitialResidual* r0) {
  ScopedRegion region("mfsi::kernels::krylov::cg");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);
  const RealView r = workResidual(r0, r_, n, "mfsi::kernels::krylov::cg::r");
  ensureSize(z_, nc, "mfsi::kernels::krylov::cg::z");
  ensureSize(p_, nc, "mfsi::kernels::krylov::cg::p");
  ensureSize(q_, n, "mfsi::kernels::krylov::cg::q");
  const RealView z = z_, p = p_, q = q_;
  const bool project = options_.nullSpace == NullSpace::Constant;
  const double nGlobal = comm_.globalSum(static_cast<double>(n));
  const bool lattice = lattice_.matches(A);

  KrylovResult res;
  const Start s0 = start(exec, comm_, options_, A, b, x, r, r0, nGlobal, res);
  double rr = s0.rr, l1 = s0.l1;
  const Stop stop = s0.stop;
  auto finish = [&](KrylovStatus status) {
    res.status = status;
    res.converged = status == KrylovStatus::Converged;
    res.finalResidual = std::sqrt(rr);
    res.finalResidualL1 = l1;
    if (project) projectMean(exec, comm_, n, x);
    return res;
  };
  if (!finite(rr)) return finish(KrylovStatus::NotFinite);
  if (stop.met(rr, l1)) return finish(KrylovStatus::Converged);

  // {r.z, sum z, sum r}: with projection, r.(z - m) = r.z - m sum r.
  auto precondDots = [&]() {
    const auto d = reduce<3>(
        exec, comm_, "mfsi::kernels::krylov::cg::rz", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          acc[0] += r(i) * z(i);
          acc[1] += z(i);
          acc[2] += r(i);
        });
    const double m = project ? d[1] / nGlobal : 0.0;
    return std::array<double, 2>{d[0] - m * d[2], m};
  };
  // p = z - m + beta p (beta = 0: p is not read).
  auto direction = [&](double beta, double m) {
    Kokkos::parallel_for(
        "mfsi::kernels::krylov::cg::direction", RangePolicy(exec, 0, n),
        KOKKOS_LAMBDA(lid_t i) { p(i) = beta == 0.0 ? z(i) - m : z(i) - m + beta * p(i); });
  };

  M.apply(exec, r, z);
  auto [rz, m] = precondDots();
  if (!finite(rz)) return finish(KrylovStatus::NotFinite);
  direction(0.0, m);

  for (int it = 1; it <= options_.maxIterations; ++it) {
    double pq = 0.0;
    if (lattice) {
      comm_.updateGhosts(exec, p);
      pq = lattice_.spmvDot(exec, comm_, p, q, p);
    } else {
      pq = blas::spmvDotOverlapped(exec, comm_, A, p, q, p);
    }
    if (!finite(pq)) return finish(KrylovStatus::NotFinite);
    if (pq == 0.0 || rz == 0.0) return finish(KrylovStatus::Breakdown);
    const double alpha = rz / pq;
    const auto un = reduce<2>(
        exec, comm_, "mfsi::kernels::krylov::cg::update", n, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          x(i) += alpha * p(i);
          const double ri = r(i) - alpha * q(i);
          r(i) = ri;
          acc[0] += ri * ri;
          acc[1] += kmath::fabs(ri);
        });
    rr = un[0];
    l1 = un[1];
    res.iterations = it;
    if (!finite(rr)) return finish(KrylovStatus::NotFinite);
    if (stop.met(rr, l1)) return finish(KrylovStatus::Converged);
    M.apply(exec, r, z);
    const auto [rzNew, mNew] = precondDots();
    if (!finite(rzNew)) return finish(KrylovStatus::NotFinite);
    const double beta = rzNew / rz;
    rz = rzNew;
    direction(beta, mNew);
  }
  return finish(KrylovStatus::MaxIterations);
}

// ---------------------------------------------------------------------------------------------
// BiCGStab with right preconditioning: solves A M^{-1} y = b, x = M^{-1} y, so the residual
// monitored is the true (unpreconditioned) one. s overwrites r. Fused kernels: v = A phat with
// rhat.v; s = r - alpha v with {s.s, |s|_1}; t = A shat with {t.s, t.t}; the x/r update with
// {r.r, rhat.r, |r|_1}.
// ---------------------------------------------------------------------------------------------
KrylovResult BiCGStab::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                             Preconditioner& M) {
  return run(exec, A, b, x, M, nullptr);
}

KrylovResult BiCGStab::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                             Preconditioner& M, const InitialResidual& r0) {
  return run(exec, A, b, x, M, &r0);
}

KrylovResult BiCGStab::run(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                           Preconditioner& M, const InitialResidual* r0) {
  ScopedRegion region("mfsi::kernels::krylov::bicgstab");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);
  const RealView r = workResidual(r0, r_, n, "mfsi::kernels::krylov::bicgstab::r");
  ensureSize(rhat_, n, "mfsi::kernels::krylov::bicgstab::rhat");
  ensureSize(p_, n, "mfsi::kernels::krylov::bicgstab::p");
  ensureSize(v_, n, "mfsi::kernels::krylov::bicgstab::v");
  ensureSize(phat_, nc, "mfsi::kernels::krylov::bicgstab::phat");
  ensureSize(shat_, nc, "mfsi::kernels::krylov::bicgstab::shat");
  ensureSize(t_, n, "mfsi::kernels::krylov::bicgstab::t");
  const RealView rhat = rhat_, p = p_, v = v_, phat = phat_, shat = shat_, t = t_;
  const bool project = options_.nullSpace == NullSpace::Constant;
  const double nGlobal = comm_.globalSum(static_cast<double>(n));

  KrylovResult res;
  const Start s0 = start(exec, comm_, options_, A, b, x, r, r0, nGlobal, res);
  double rr = s0.rr, l1 = s0.l1;
  const Stop stop = s0.stop;
  auto finish = [&](KrylovStatus status) {
    res.status = status;
    res.converged = status == KrylovStatus::Converged;
    res.finalResidual = std::sqrt(rr);
    res.finalResidualL1 = l1;
    if (project) projectMean(exec, comm_, n, x);
    return res;
  };
  if (!finite(rr)) return finish(KrylovStatus::NotFinite);
  if (stop.met(rr, l1)) return finish(KrylovStatus::Converged);

  Kokkos::deep_copy(exec, Kokkos::subview(rhat, std::make_pair(lid_t(0), n)),
                    Kokkos::subview(r, std::make_pair(lid_t(0), n)));
  double rho = rr;  // rhat.r with rhat = r0
  double rhoOld = 1.0, alpha = 1.0, omega = 1.0;
  for (int it = 1; it <= options_.maxIterations; ++it) {
    if (rho == 0.0) return finish(KrylovStatus::Breakdown);
    if (it == 1) {
      Kokkos::deep_copy(exec, p, Kokkos::subview(r, std::make_pair(lid_t(0), n)));
    } else {
      const double beta = (rho / rhoOld) * (alpha / omega);
      Kokkos::parallel_for(
          "mfsi::kernels::krylov::bicgstab::direction", RangePolicy(exec, 0, n),
          KOKKOS_LAMBDA(lid_t i) { p(i) = r(i) + beta * (p(i) - omega * v(i)); });
    }
    M.apply(exec, p, phat);
    if (project) projectMean(exec, comm_, n, phat);
    comm_.updateGhosts(exec, phat);
    const double rv = blas::spmvDot(exec, comm_, A, phat, v, rhat);
    if (!finite(rv)) return finish(KrylovStatus::NotFinite);
    if (rv == 0.0) return finish(KrylovStatus::Breakdown);
    alpha = rho / rv;
    res.iterations = it;
    const double a = alpha;
    const auto sn = reduce<2>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab::s", n, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          const double si = r(i) - a * v(i);
          r(i) = si;
          acc[0] += si * si;
          acc[1] += kmath::fabs(si);
        });
    rr = sn[0];
    l1 = sn[1];
    if (!finite(rr)) return finish(KrylovStatus::NotFinite);
    if (stop.met(rr, l1)) {
      blas::axpy(exec, n, alpha, phat, x);
      return finish(KrylovStatus::Converged);
    }
    M.apply(exec, r, shat);
    if (project) projectMean(exec, comm_, n, shat);
    comm_.updateGhosts(exec, shat);
    const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
    const ConstRealView val = A.values;
    const auto ts = reduce<2>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab::t", n, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          double ti = 0.0;
          for (lid_t k = rowPtr(i); k < rowPtr(i + 1); ++k) ti += val(k) * shat(colIdx(k));
          t(i) = ti;
          acc[0] += ti * r(i);
          acc[1] += ti * ti;
        });
    if (!finite(ts[0]) || !finite(ts[1])) return finish(KrylovStatus::NotFinite);
    if (ts[1] == 0.0) return finish(KrylovStatus::Breakdown);
    omega = ts[0] / ts[1];
    if (omega == 0.0) return finish(KrylovStatus::Breakdown);
    const double w = omega;
    const auto rn = reduce<3>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab::update", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          x(i) += a * phat(i) + w * shat(i);
          const double ri = r(i) - w * t(i);
          r(i) = ri;
          acc[0] += ri * ri;
          acc[1] += rhat(i) * ri;
          acc[2] += kmath::fabs(ri);
        });
    rr = rn[0];
    l1 = rn[2];
    if (!finite(rr) || !finite(rn[1])) return finish(KrylovStatus::NotFinite);
    if (stop.met(rr, l1)) return finish(KrylovStatus::Converged);
    rhoOld = rho;
    rho = rn[1];
  }
  return finish(KrylovStatus::MaxIterations);
}

// ---------------------------------------------------------------------------------------------
// Three-column BiCGStab (see the class comment). Every column c runs exactly the recurrence of
// BiCGStab::run with M = diag(A)^{-1}; the kernels loop over the columns still active and skip
// the others. The preconditioned vectors phat = inv .* p and shat = inv .* s are never stored:
// the x update forms inv_i * p_i on the fly (bitwise a stored phat's value) and the SpMV gathers
// scale the coefficient instead, (a_ij * inv_j) * p_j, one product for the three columns (a
// stored phat would give a_ij * (inv_j * p_j): equal to round-off). This saves writing and
// re-reading two n x 3 vectors per iteration for one read of inv. Per iteration (all columns
// together) one direction kernel and four fused reductions:
//   K1  p = r + beta (p - omega v)                            (iteration 1: p = r, rhat = r)
//   K2  v = A (inv .* p);          sums {rhat.v}              -> alpha
//   K3  s = r - alpha v (in r);    {s.s, |s|_1}               -> half-step test
//   K4  t = A (inv .* s);          {t.s, t.t}                 -> omega  (columns not converged)
//   K5  x += alpha inv .* p + omega inv .* s, r = s - omega t; {r.r, rhat.r, |r|_1}
//       (a column converged at the half step gets x += alpha inv .* p here, as BiCGStab's axpy)
// ---------------------------------------------------------------------------------------------
BiCGStab3::BiCGStab3(const KrylovOptions& options, const SolverComm& comm)
    : options_{options, options, options}, comm_(comm) {}

std::array<KrylovResult, 3> BiCGStab3::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                             const Real3View& x, const ConstRealView& invDiag) {
  return run(exec, A, b, x, invDiag, nullptr);
}

std::array<KrylovResult, 3> BiCGStab3::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                             const Real3View& x, const ConstRealView& invDiag,
                                             const InitialResidual3& r0) {
  return run(exec, A, b, x, invDiag, &r0);
}

std::array<KrylovResult, 3> BiCGStab3::run(const ExecSpace& exec, const CsrMatrix& A, const ConstReal3View& b,
                                           const Real3View& x, const ConstRealView& invDiag,
                                           const InitialResidual3* r0) {
  ScopedRegion region("mfsi::kernels::krylov::bicgstab3");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);
  for (const auto& o : options_)
    MFSI_CHECK(o.nullSpace == NullSpace::None, "BiCGStab3: null-space projection is not supported");
  MFSI_CHECK(invDiag.extent(0) >= static_cast<std::size_t>(nc) && b.extent(0) >= static_cast<std::size_t>(n) &&
                 x.extent(0) >= static_cast<std::size_t>(nc),
             "BiCGStab3: vector sizes (inverse diagonal " << invDiag.extent(0) << ", b " << b.extent(0) << ", x "
                                                          << x.extent(0) << ") do not fit the matrix (" << n
                                                          << " rows, " << nc << " columns)");
  Real3View r;
  if (r0 != nullptr) {
    MFSI_CHECK(r0->r.extent(0) >= static_cast<std::size_t>(nc), "BiCGStab3: the given initial residual has "
                                                                    << r0->r.extent(0) << " rows, the matrix " << nc
                                                                    << " columns");
    r = r0->r;
  } else {
    ensureSize(r_, nc, "mfsi::kernels::krylov::bicgstab3::r");
    r = r_;
  }
  ensureSize(rhat_, n, "mfsi::kernels::krylov::bicgstab3::rhat");
  ensureSize(p_, nc, "mfsi::kernels::krylov::bicgstab3::p");
  ensureSize(v_, n, "mfsi::kernels::krylov::bicgstab3::v");
  ensureSize(t_, n, "mfsi::kernels::krylov::bicgstab3::t");
  const Real3View rhat = rhat_, p = p_, v = v_, t = t_;
  const ConstRealView inv = invDiag;
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const ConstRealView val = A.values;
  const blas::detail::RunView R = blas::detail::useRuns(A) ? blas::detail::RunView(A) : blas::detail::RunView{};
  const double* invp = inv.data();

  // Start: residuals and their norms, stopping tests.
  std::array<double, 3> rr{}, l1{};
  if (r0 != nullptr) {
    rr = r0->rr;
    l1 = r0->l1;
  } else {
    comm_.updateGhosts(exec, x);
    const auto norms = blas::residualNorms(exec, comm_, A, x, b, r);
    for (int c = 0; c < 3; ++c) {
      rr[c] = norms[c].rr;
      l1[c] = norms[c].l1;
    }
  }
  std::array<double, 3> ref{};
  for (int c = 0; c < 3; ++c) ref[c] = std::sqrt(rr[c]);
  if (std::any_of(options_.begin(), options_.end(),
                  [](const KrylovOptions& o) { return o.relativeTo == ResidualReference::RightHandSide; })) {
    const auto bb = reduce<3>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab3::rhsNorm", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          for (int c = 0; c < 3; ++c) acc[c] += b(i, c) * b(i, c);
        });
    for (int c = 0; c < 3; ++c)
      if (options_[c].relativeTo == ResidualReference::RightHandSide) ref[c] = std::sqrt(bb[c]);
  }
  std::array<Stop, 3> stop;
  std::array<KrylovResult, 3> res;
  std::array<bool, 3> active{};
  for (int c = 0; c < 3; ++c) {
    stop[c].target = std::max(options_[c].absTol, options_[c].relTol * ref[c]);
    stop[c].l1Target = options_[c].l1AbsTol;
    res[c].initialResidual = std::sqrt(rr[c]);
    res[c].initialResidualL1 = l1[c];
    active[c] = true;
  }
  auto finish = [&](int c, KrylovStatus status) {
    res[c].status = status;
    res[c].converged = status == KrylovStatus::Converged;
    res[c].finalResidual = std::sqrt(rr[c]);
    res[c].finalResidualL1 = l1[c];
    active[c] = false;
  };
  for (int c = 0; c < 3; ++c) {
    if (!finite(rr[c]))
      finish(c, KrylovStatus::NotFinite);
    else if (stop[c].met(rr[c], l1[c]))
      finish(c, KrylovStatus::Converged);
  }

  // Per-column recurrence scalars, as in BiCGStab::run.
  std::array<double, 3> rho = rr, rhoOld{1.0, 1.0, 1.0}, alpha{1.0, 1.0, 1.0}, omega{1.0, 1.0, 1.0};
  enum Mode : int { Frozen = 0, HalfStep = 1, FullStep = 2 };
  for (int it = 1;; ++it) {
    for (int c = 0; c < 3; ++c) {
      if (!active[c]) continue;
      if (it > options_[c].maxIterations)
        finish(c, KrylovStatus::MaxIterations);
      else if (rho[c] == 0.0)
        finish(c, KrylovStatus::Breakdown);
    }
    if (!active[0] && !active[1] && !active[2]) break;

    // K1: the directions (their preconditioned copies are formed where they are used).
    Kokkos::Array<int, 3> on;
    Kokkos::Array<double, 3> beta, om;
    for (int c = 0; c < 3; ++c) {
      on[c] = active[c] ? 1 : 0;
      beta[c] = it == 1 ? 0.0 : (rho[c] / rhoOld[c]) * (alpha[c] / omega[c]);
      om[c] = omega[c];
    }
    const bool first = it == 1;
    Kokkos::parallel_for(
        "mfsi::kernels::krylov::bicgstab3::direction", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
          for (int c = 0; c < 3; ++c) {
            if (!on[c]) continue;
            if (first) {
              rhat(i, c) = r(i, c);
              p(i, c) = r(i, c);
            } else {
              p(i, c) = r(i, c) + beta[c] * (p(i, c) - om[c] * v(i, c));
            }
          }
        });

    // K2: v = A phat with phat_j = inv_j p_j formed in the gather (A and inv read once for the
    // three columns; the run path forms the active columns only), and rhat.v.
    comm_.updateGhosts(exec, p);
    const int vMask = (active[0] ? 1 : 0) | (active[1] ? 2 : 0) | (active[2] ? 4 : 0);
    const auto rv = blas::detail::useRuns(A)
        ? blas::detail::reduceRuns<3>(
              exec, comm_, "mfsi::kernels::krylov::bicgstab3::v", A,
              [=](lid_t run) { jacobiRun3(vMask, R, run, invp, p.data(), v.data()); },
              [=](lid_t i, Sums<3>& acc) {
                for (int c = 0; c < 3; ++c) acc[c] += rhat(i, c) * v(i, c);
              })
        : reduce<3>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab3::v", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          double av[3];
          jacobiRow3(rowPtr, colIdx, val, inv, p, i, av);
          // Written for every column: v of a frozen column is never read again (cheaper than
          // branching per row).
          for (int c = 0; c < 3; ++c) {
            v(i, c) = av[c];
            acc[c] += rhat(i, c) * av[c];
          }
        });
    Kokkos::Array<double, 3> al;
    for (int c = 0; c < 3; ++c) {
      if (!active[c]) continue;
      if (!finite(rv[c])) {
        finish(c, KrylovStatus::NotFinite);
      } else if (rv[c] == 0.0) {
        finish(c, KrylovStatus::Breakdown);
      } else {
        alpha[c] = rho[c] / rv[c];
        res[c].iterations = it;
      }
    }
    for (int c = 0; c < 3; ++c) {
      on[c] = active[c] ? 1 : 0;
      al[c] = alpha[c];
    }

    // K3: s = r - alpha v (in r), with {s.s, |s|_1}.
    const auto sn = reduce<6>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab3::s", n, KOKKOS_LAMBDA(lid_t i, Sums<6> & acc) {
          for (int c = 0; c < 3; ++c) {
            if (!on[c]) continue;
            const double si = r(i, c) - al[c] * v(i, c);
            r(i, c) = si;
            acc[c] += si * si;
            acc[3 + c] += kmath::fabs(si);
          }
        });
    Kokkos::Array<int, 3> mode;
    bool anyFull = false;
    for (int c = 0; c < 3; ++c) {
      mode[c] = Frozen;
      if (!active[c]) continue;
      rr[c] = sn[c];
      l1[c] = sn[3 + c];
      if (!finite(rr[c])) {
        finish(c, KrylovStatus::NotFinite);
      } else if (stop[c].met(rr[c], l1[c])) {
        mode[c] = HalfStep;
      } else {
        mode[c] = FullStep;
        anyFull = true;
      }
    }

    // K4: t = A shat (shat_j = inv_j s_j formed in the gather) with {t.s, t.t}, for the columns
    // going on to the full step.
    Kokkos::Array<double, 3> w;
    for (int c = 0; c < 3; ++c) w[c] = 0.0;
    if (anyFull) {
      comm_.updateGhosts(exec, r);
      const int tMask = (mode[0] == FullStep ? 1 : 0) | (mode[1] == FullStep ? 2 : 0) | (mode[2] == FullStep ? 4 : 0);
      const auto ts = blas::detail::useRuns(A)
          ? blas::detail::reduceRuns<6>(
                exec, comm_, "mfsi::kernels::krylov::bicgstab3::t", A,
                [=](lid_t run) { jacobiRun3(tMask, R, run, invp, r.data(), t.data()); },
                [=](lid_t i, Sums<6>& acc) {
                  for (int c = 0; c < 3; ++c) {
                    acc[c] += t(i, c) * r(i, c);
                    acc[3 + c] += t(i, c) * t(i, c);
                  }
                })
          : reduce<6>(
          exec, comm_, "mfsi::kernels::krylov::bicgstab3::t", n, KOKKOS_LAMBDA(lid_t i, Sums<6> & acc) {
            double at[3];
            jacobiRow3(rowPtr, colIdx, val, inv, r, i, at);
            for (int c = 0; c < 3; ++c) {  // every column, as in K2
              t(i, c) = at[c];
              acc[c] += at[c] * r(i, c);
              acc[3 + c] += at[c] * at[c];
            }
          });
      for (int c = 0; c < 3; ++c) {
        if (mode[c] != FullStep) continue;
        if (!finite(ts[c]) || !finite(ts[3 + c])) {
          finish(c, KrylovStatus::NotFinite);
        } else if (ts[3 + c] == 0.0) {
          finish(c, KrylovStatus::Breakdown);
        } else {
          omega[c] = ts[c] / ts[3 + c];
          w[c] = omega[c];
          if (omega[c] == 0.0) finish(c, KrylovStatus::Breakdown);
        }
        if (!active[c]) mode[c] = Frozen;
      }
    }

    // K5: x and r updates with {r.r, rhat.r, |r|_1}; half-step columns only get x += alpha phat.
    if (mode[0] == Frozen && mode[1] == Frozen && mode[2] == Frozen) continue;
    const auto rn = reduce<9>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab3::update", n, KOKKOS_LAMBDA(lid_t i, Sums<9> & acc) {
          const double d = inv(i);
          for (int c = 0; c < 3; ++c) {
            if (mode[c] == FullStep) {
              const double si = r(i, c);
              x(i, c) += al[c] * (d * p(i, c)) + w[c] * (d * si);
              const double ri = si - w[c] * t(i, c);
              r(i, c) = ri;
              acc[c] += ri * ri;
              acc[3 + c] += rhat(i, c) * ri;
              acc[6 + c] += kmath::fabs(ri);
            } else if (mode[c] == HalfStep) {
              x(i, c) += al[c] * (d * p(i, c));
            }
          }
        });
    for (int c = 0; c < 3; ++c) {
      if (mode[c] == HalfStep) {
        finish(c, KrylovStatus::Converged);
      } else if (mode[c] == FullStep) {
        rr[c] = rn[c];
        l1[c] = rn[6 + c];
        if (!finite(rr[c]) || !finite(rn[3 + c])) {
          finish(c, KrylovStatus::NotFinite);
        } else if (stop[c].met(rr[c], l1[c])) {
          finish(c, KrylovStatus::Converged);
        } else {
          rhoOld[c] = rho[c];
          rho[c] = rn[3 + c];
        }
      }
    }
  }
  return res;
}

}  // namespace mfsi
