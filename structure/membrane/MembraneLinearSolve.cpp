#include "structure/membrane/MembraneLinearSolve.hpp"

#include <cmath>

namespace mfsi {

void projectConstraints(const ExecSpace& exec, const MembraneConstraints& c, const ConstRealView& in,
                        const RealView& out) {
  auto kind = c.kind;
  auto dir = c.direction;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::project", RangePolicy(exec, 0, static_cast<lid_t>(kind.extent(0))),
      KOKKOS_LAMBDA(lid_t n) {
        real v[3] = {in(3 * n), in(3 * n + 1), in(3 * n + 2)};
        membrane::projectNode(kind(n), dir(n, 0), dir(n, 1), dir(n, 2), v);
        for (int k = 0; k < 3; ++k) out(3 * n + k) = v[k];
      });
}

namespace {

/// z = P D^-1 r.
void precondition(const ExecSpace& exec, const MembraneConstraints& c, const ConstRealView& invDiag,
                  const ConstRealView& r, const RealView& z) {
  auto kind = c.kind;
  auto dir = c.direction;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::cg::precondition", RangePolicy(exec, 0, static_cast<lid_t>(kind.extent(0))),
      KOKKOS_LAMBDA(lid_t n) {
        real v[3];
        for (int k = 0; k < 3; ++k) v[k] = invDiag(3 * n + k) * r(3 * n + k);
        membrane::projectNode(kind(n), dir(n, 0), dir(n, 1), dir(n, 2), v);
        for (int k = 0; k < 3; ++k) z(3 * n + k) = v[k];
      });
}

}  // namespace

MembraneCgResult MembraneCg::solve(const ExecSpace& exec, const CsrMatrix& K, const MembraneConstraints& c,
                                   const ConstRealView& b, const RealView& x, real relTol, int maxIterations) {
  ScopedRegion region("mfsi::structure::membrane::cg");
  const lid_t n = K.nRows, nNodes = n / 3;
  if (static_cast<lid_t>(r_.extent(0)) != n) {
    r_ = RealView("mfsi::structure::membrane::cg::r", n);
    z_ = RealView("mfsi::structure::membrane::cg::z", n);
    p_ = RealView("mfsi::structure::membrane::cg::p", n);
    q_ = RealView("mfsi::structure::membrane::cg::q", n);
    invDiag_ = RealView("mfsi::structure::membrane::cg::invDiag", n);
  }
  const ConstIndexView rowPtr = K.rowPtr, colIdx = K.colIdx, diagIdx = K.diagIdx;
  const ConstRealView values = K.values;
  auto kind = c.kind;
  auto dir = c.direction;
  auto invDiag = invDiag_;
  auto r = r_, z = z_, p = p_, q = q_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::cg::jacobi", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        const real d = diagIdx(i) >= 0 ? values(diagIdx(i)) : 0;
        invDiag(i) = d > 0 ? 1 / d : 0;
      });
  blas::fill(exec, n, 0.0, x);
  projectConstraints(exec, c, b, r_);
  precondition(exec, c, invDiag_, r_, z_);
  Kokkos::deep_copy(exec, p_, z_);
  // The loop runs three fused kernels per iteration (node-wise, so the 3 x 3 projection sees a
  // node's three rows): q = P K p with p.q; x, r update with the preconditioner z = P D^-1 r and
  // r.r, r.z; p = z + beta p. Reductions are blas::reduce's deterministic blocked sums.
  const auto start = blas::reduce<2>(exec, comm_, "mfsi::structure::membrane::cg::start", n,
                                     KOKKOS_LAMBDA(lid_t i, blas::Sums<2> & s) {
                                       s[0] += r(i) * r(i);
                                       s[1] += r(i) * z(i);
                                     });
  MembraneCgResult res;
  const real bnorm = std::sqrt(start[0]);
  if (bnorm == 0) {
    res.converged = true;
    return res;
  }
  real rz = start[1];
  real rnorm = bnorm;
  for (int it = 0; it < maxIterations; ++it) {
    const real pq = blas::reduce<1>(exec, comm_, "mfsi::structure::membrane::cg::operator", nNodes,
                                    KOKKOS_LAMBDA(lid_t node, blas::Sums<1> & s) {
                                      real v[3];
                                      for (int k = 0; k < 3; ++k) {
                                        const lid_t row = 3 * node + k;
                                        real y = 0;
                                        for (lid_t e = rowPtr(row); e < rowPtr(row + 1); ++e)
                                          y += values(e) * p(colIdx(e));
                                        v[k] = y;
                                      }
                                      membrane::projectNode(kind(node), dir(node, 0), dir(node, 1), dir(node, 2), v);
                                      for (int k = 0; k < 3; ++k) {
                                        q(3 * node + k) = v[k];
                                        s[0] += p(3 * node + k) * v[k];
                                      }
                                    })[0];
    if (!(pq > 0)) {
      res.negativeCurvature = true;
      break;
    }
    const real alpha = rz / pq;
    const auto sums = blas::reduce<2>(exec, comm_, "mfsi::structure::membrane::cg::update", nNodes,
                                      KOKKOS_LAMBDA(lid_t node, blas::Sums<2> & s) {
                                        real v[3];
                                        for (int k = 0; k < 3; ++k) {
                                          const lid_t i = 3 * node + k;
                                          x(i) += alpha * p(i);
                                          r(i) -= alpha * q(i);
                                          v[k] = invDiag(i) * r(i);
                                          s[0] += r(i) * r(i);
                                        }
                                        membrane::projectNode(kind(node), dir(node, 0), dir(node, 1), dir(node, 2), v);
                                        for (int k = 0; k < 3; ++k) {
                                          z(3 * node + k) = v[k];
                                          s[1] += r(3 * node + k) * v[k];
                                        }
                                      });
    rnorm = std::sqrt(sums[0]);
    res.iterations = it + 1;
    if (!std::isfinite(rnorm)) break;
    if (rnorm <= relTol * bnorm) {
      res.converged = true;
      break;
    }
    const real beta = sums[1] / rz;
    rz = sums[1];
    Kokkos::parallel_for(
        "mfsi::structure::membrane::cg::direction", RangePolicy(exec, 0, n),
        KOKKOS_LAMBDA(lid_t i) { p(i) = z(i) + beta * p(i); });
  }
  res.relativeResidual = rnorm / bnorm;
  return res;
}

}  // namespace mfsi
