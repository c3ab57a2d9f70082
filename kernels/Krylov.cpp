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

bool finite(double v) { return std::isfinite(v); }

/// Shared set-up of both methods: r = b - A x (projected), the initial residual norm, the target.
struct Start {
  double rr = 0.0;
  double target = 0.0;
};

Start start(const ExecSpace& exec, const SolverComm& comm, const KrylovOptions& opt, const CsrMatrix& A,
            const ConstRealView& b, const RealView& x, const RealView& r, double nGlobal, KrylovResult& res) {
  const bool project = opt.nullSpace == NullSpace::Constant;
  comm.updateGhosts(exec, x);
  double rr = blas::residual(exec, comm, A, x, b, r);
  if (project) {
    blas::shift(exec, A.nRows, -blas::mean(exec, comm, A.nRows, r), r);
    rr = blas::dot(exec, comm, A.nRows, r, r);
  }
  Start s;
  s.rr = rr;
  res.initialResidual = res.finalResidual = std::sqrt(rr);
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
  s.target = std::max(opt.absTol, opt.relTol * ref);
  return s;
}

/// Project z onto zero mean (constant null space).
void projectMean(const ExecSpace& exec, const SolverComm& comm, lid_t n, const RealView& z) {
  blas::shift(exec, n, -blas::mean(exec, comm, n, z), z);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Conjugate gradients. Per iteration: one SpMV fused with p.Ap, one update of x and r fused with
// r.r, one preconditioner apply, one reduction {r.z, sum z, sum r} and the direction update.
// With a constant null space, z is projected inside the direction update (p = z - mean(z) + beta
// p) and r.z corrected accordingly, so projection costs no extra pass.
// ---------------------------------------------------------------------------------------------
KrylovResult ConjugateGradient::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                      const RealView& x, Preconditioner& M) {
  ScopedRegion region("mfsi::kernels::krylov::cg");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);
  ensureSize(r_, n, "mfsi::kernels::krylov::cg::r");
  ensureSize(z_, nc, "mfsi::kernels::krylov::cg::z");
  ensureSize(p_, nc, "mfsi::kernels::krylov::cg::p");
  ensureSize(q_, n, "mfsi::kernels::krylov::cg::q");
  const RealView r = r_, z = z_, p = p_, q = q_;
  const bool project = options_.nullSpace == NullSpace::Constant;
  const double nGlobal = comm_.globalSum(static_cast<double>(n));

  KrylovResult res;
  const Start s0 = start(exec, comm_, options_, A, b, x, r, nGlobal, res);
  double rr = s0.rr;
  const double target = s0.target;
  auto finish = [&](KrylovStatus status) {
    res.status = status;
    res.converged = status == KrylovStatus::Converged;
    res.finalResidual = std::sqrt(rr);
    if (project) projectMean(exec, comm_, n, x);
    return res;
  };
  if (!finite(rr)) return finish(KrylovStatus::NotFinite);
  if (std::sqrt(rr) <= target) return finish(KrylovStatus::Converged);

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
    comm_.updateGhosts(exec, p);
    const double pq = blas::spmvDot(exec, comm_, A, p, q, p);
    if (!finite(pq)) return finish(KrylovStatus::NotFinite);
    if (pq == 0.0 || rz == 0.0) return finish(KrylovStatus::Breakdown);
    const double alpha = rz / pq;
    rr = reduce<1>(
        exec, comm_, "mfsi::kernels::krylov::cg::update", n, KOKKOS_LAMBDA(lid_t i, Sums<1> & acc) {
          x(i) += alpha * p(i);
          const double ri = r(i) - alpha * q(i);
          r(i) = ri;
          acc[0] += ri * ri;
        })[0];
    res.iterations = it;
    if (!finite(rr)) return finish(KrylovStatus::NotFinite);
    if (std::sqrt(rr) <= target) return finish(KrylovStatus::Converged);
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
// rhat.v; s = r - alpha v with s.s; t = A shat with {t.s, t.t}; the x/r update with {r.r, rhat.r}.
// ---------------------------------------------------------------------------------------------
KrylovResult BiCGStab::solve(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b, const RealView& x,
                             Preconditioner& M) {
  ScopedRegion region("mfsi::kernels::krylov::bicgstab");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);
  ensureSize(r_, n, "mfsi::kernels::krylov::bicgstab::r");
  ensureSize(rhat_, n, "mfsi::kernels::krylov::bicgstab::rhat");
  ensureSize(p_, n, "mfsi::kernels::krylov::bicgstab::p");
  ensureSize(v_, n, "mfsi::kernels::krylov::bicgstab::v");
  ensureSize(phat_, nc, "mfsi::kernels::krylov::bicgstab::phat");
  ensureSize(shat_, nc, "mfsi::kernels::krylov::bicgstab::shat");
  ensureSize(t_, n, "mfsi::kernels::krylov::bicgstab::t");
  const RealView r = r_, rhat = rhat_, p = p_, v = v_, phat = phat_, shat = shat_, t = t_;
  const bool project = options_.nullSpace == NullSpace::Constant;
  const double nGlobal = comm_.globalSum(static_cast<double>(n));

  KrylovResult res;
  const Start s0 = start(exec, comm_, options_, A, b, x, r, nGlobal, res);
  double rr = s0.rr;
  const double target = s0.target;
  auto finish = [&](KrylovStatus status) {
    res.status = status;
    res.converged = status == KrylovStatus::Converged;
    res.finalResidual = std::sqrt(rr);
    if (project) projectMean(exec, comm_, n, x);
    return res;
  };
  if (!finite(rr)) return finish(KrylovStatus::NotFinite);
  if (std::sqrt(rr) <= target) return finish(KrylovStatus::Converged);

  Kokkos::deep_copy(exec, rhat, r);
  double rho = rr;  // rhat.r with rhat = r0
  double rhoOld = 1.0, alpha = 1.0, omega = 1.0;
  for (int it = 1; it <= options_.maxIterations; ++it) {
    if (rho == 0.0) return finish(KrylovStatus::Breakdown);
    if (it == 1) {
      Kokkos::deep_copy(exec, p, r);
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
    rr = reduce<1>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab::s", n, KOKKOS_LAMBDA(lid_t i, Sums<1> & acc) {
          const double si = r(i) - a * v(i);
          r(i) = si;
          acc[0] += si * si;
        })[0];
    if (!finite(rr)) return finish(KrylovStatus::NotFinite);
    if (std::sqrt(rr) <= target) {
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
    const auto rn = reduce<2>(
        exec, comm_, "mfsi::kernels::krylov::bicgstab::update", n, KOKKOS_LAMBDA(lid_t i, Sums<2> & acc) {
          x(i) += a * phat(i) + w * shat(i);
          const double ri = r(i) - w * t(i);
          r(i) = ri;
          acc[0] += ri * ri;
          acc[1] += rhat(i) * ri;
        });
    rr = rn[0];
    if (!finite(rr) || !finite(rn[1])) return finish(KrylovStatus::NotFinite);
    if (std::sqrt(rr) <= target) return finish(KrylovStatus::Converged);
    rhoOld = rho;
    rho = rn[1];
  }
  return finish(KrylovStatus::MaxIterations);
}

}  // namespace mfsi
