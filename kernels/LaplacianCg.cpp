#include "kernels/LaplacianCg.hpp"

#include "kernels/Blas.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi {

namespace {

/// One row of the operator: sum_j w_ij (x_i - x_j), component c.
/// One row of the operator: sum_j w_ij (x_i - x_j), projected on the tangent plane of a sliding node.
struct LaplacianRow {
  ConstIndexView off, nb;
  ConstRealView w;
  ConstReal3View sn;
  bool weighted, sliding;
  KOKKOS_INLINE_FUNCTION void operator()(const ConstReal3View& x, lid_t i, real y[3]) const {
    y[0] = y[1] = y[2] = 0;
    for (lid_t k = off(i); k < off(i + 1); ++k) {
      const lid_t j = nb(k);
      const real wk = weighted ? w(k) : real(1);
      for (int c = 0; c < 3; ++c) y[c] += wk * (x(i, c) - x(j, c));
    }
    if (sliding) {
      const real yn = y[0] * sn(i, 0) + y[1] * sn(i, 1) + y[2] * sn(i, 2);
      for (int c = 0; c < 3; ++c) y[c] -= yn * sn(i, c);
    }
  }
};

LaplacianRow rowOf(const SmoothingGraph& g) {
  return LaplacianRow{g.offsets, g.neighbours, g.weights, g.slideNormal, g.weights.extent(0) > 0,
                      g.slideNormal.extent(0) > 0};
}

void allocate(LaplacianCgWork& w, lid_t n) {
  if (static_cast<lid_t>(w.r.extent(0)) == n) return;
  w.r = Real3View("mfsi::kernels::laplacianCg::r", n);
  w.p = Real3View("mfsi::kernels::laplacianCg::p", n);
  w.q = Real3View("mfsi::kernels::laplacianCg::q", n);
  w.inverseDiagonal = RealView("mfsi::kernels::laplacianCg::inverseDiagonal", n);
}

}  // namespace

LaplacianCgResult laplacianCg(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, LaplacianCgWork& work,
                              const LaplacianCgOptions& options) {
  const lid_t n = g.nNodes();
  allocate(work, n);
  const LaplacianRow row = rowOf(g);
  const auto fixed = g.fixed;
  const Real3View r = work.r, p = work.p, q = work.q;
  const RealView dinv = work.inverseDiagonal;
  const SolverComm comm;
  // r = -L d on the free nodes; z = D^-1 r; p = z.
  const auto s0 = blas::reduce<3>(exec, comm, "mfsi::kernels::laplacianCg::start", n,
                                  KOKKOS_LAMBDA(lid_t i, blas::Sums<3> & acc) {
                                    real v[3] = {0, 0, 0};
                                    real diag = 0;
                                    if (fixed(i) == 0) {
                                      row(d, i, v);
                                      for (lid_t k = row.off(i); k < row.off(i + 1); ++k)
                                        diag += row.weighted ? row.w(k) : real(1);
                                    }
                                    const real inv = diag > 0 ? real(1) / diag : real(0);
                                    dinv(i) = inv;
                                    for (int c = 0; c < 3; ++c) {
                                      r(i, c) = -v[c];
                                      p(i, c) = -v[c] * inv;
                                      acc[0] += v[c] * v[c];
                                      acc[1] += v[c] * v[c] * inv;
                                      acc[2] += diag * diag * d(i, c) * d(i, c);
                                    }
                                  });
  LaplacianCgResult res;
  res.initialResidual = res.residual = std::sqrt(s0[0]);
  double rz = s0[1];
  // The residual's round-off level: sum_j w_ij d_i is computed with relative errors of ~1e-16.
  const double floor = 1e-13 * std::sqrt(s0[2]);
  const double target = std::max({options.absTol, options.relTol * res.initialResidual, floor});
  if (!(res.initialResidual > target)) {
    res.converged = true;
    return res;
  }
  for (int it = 0; it < options.maxIterations; ++it) {
    const auto pq = blas::reduce<1>(exec, comm, "mfsi::kernels::laplacianCg::apply", n,
                                    KOKKOS_LAMBDA(lid_t i, blas::Sums<1> & acc) {
                                      real v[3] = {0, 0, 0};
                                      if (fixed(i) == 0) row(p, i, v);
                                      for (int c = 0; c < 3; ++c) {
                                        q(i, c) = v[c];
                                        acc[0] += p(i, c) * v[c];
                                      }
                                    });
    if (!(pq[0] > 0)) break;  // nothing left to reduce (or a breakdown)
    const real alpha = rz / pq[0];
    const auto s = blas::reduce<2>(exec, comm, "mfsi::kernels::laplacianCg::update", n,
                                   KOKKOS_LAMBDA(lid_t i, blas::Sums<2> & acc) {
                                     for (int c = 0; c < 3; ++c) {
                                       d(i, c) += alpha * p(i, c);
                                       const real rc = r(i, c) - alpha * q(i, c);
                                       r(i, c) = rc;
                                       acc[0] += rc * rc;
                                       acc[1] += rc * rc * dinv(i);
                                     }
                                   });
    res.iterations = it + 1;
    res.residual = std::sqrt(s[0]);
    if (!std::isfinite(res.residual)) break;
    if (res.residual <= target) {
      res.converged = true;
      break;
    }
    const real beta = s[1] / rz;
    rz = s[1];
    Kokkos::parallel_for(
        "mfsi::kernels::laplacianCg::direction", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
          for (int c = 0; c < 3; ++c) p(i, c) = r(i, c) * dinv(i) + beta * p(i, c);
        });
  }
  return res;
}

}  // namespace mfsi
