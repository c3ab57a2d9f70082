#include "kernels/LaplacianCg.hpp"

#include "kernels/Blas.hpp"
#include "kernels/CsrBuild.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

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

/// The scalar graph Laplacian of one displacement component on the nodes free in it, as a CSR
/// matrix (row k for node freeNodes[k]): the diagonal sum_j w_ij over every neighbour, -w_ij for
/// free neighbours (a held neighbour's value is Dirichlet data, which the residual carries). On a
/// decomposed mesh the rows are the owned free nodes and a ghost neighbour is left out like a held
/// one: the preconditioner is then block Jacobi over the ranks, an AMG per rank.
/// `held(i)`: the node is fixed, or slides in a plane whose normal lies mostly along this
/// component (exactly what it holds for axis-aligned planes; for a slanted plane the preconditioner
/// is approximate and the CG projection keeps the iterate exact). Symmetric positive definite
/// when every connected part of the graph has a held node. Host, once per graph.
template <class Held>
CsrMatrix componentLaplacian(const SmoothingGraph& g, const Held& held, std::vector<lid_t>& freeNodes) {
  const lid_t n = g.nNodes(), owned = g.nRows();
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), g.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), g.neighbours);
  const bool weighted = g.weights.extent(0) > 0;
  auto w = Kokkos::create_mirror_view_and_copy(HostSpace(), g.weights);
  std::vector<lid_t> row(n, -1);
  freeNodes.clear();
  for (lid_t i = 0; i < owned; ++i)
    if (!held(i)) {
      row[i] = static_cast<lid_t>(freeNodes.size());
      freeNodes.push_back(i);
    }
  const lid_t m = static_cast<lid_t>(freeNodes.size());
  std::vector<std::vector<lid_t>> adjacency(m);
  for (lid_t r = 0; r < m; ++r)
    for (lid_t k = off(freeNodes[r]); k < off(freeNodes[r] + 1); ++k)
      if (row[nb(k)] >= 0) adjacency[r].push_back(row[nb(k)]);
  CsrBuildOptions o;
  o.label = "mfsi::kernels::laplacianCg::matrix";
  CsrMatrix A = buildCsr(adjacency, o);
  auto rowPtr = Kokkos::create_mirror_view_and_copy(HostSpace(), A.rowPtr);
  auto colIdx = Kokkos::create_mirror_view_and_copy(HostSpace(), A.colIdx);
  auto diagIdx = Kokkos::create_mirror_view_and_copy(HostSpace(), A.diagIdx);
  auto values = Kokkos::create_mirror_view(A.values);
  Kokkos::deep_copy(values, 0.0);
  for (lid_t r = 0; r < m; ++r) {
    const lid_t i = freeNodes[r];
    for (lid_t k = off(i); k < off(i + 1); ++k) {
      const real wk = weighted ? w(k) : real(1);
      values(diagIdx(r)) += wk;
      const lid_t c = row[nb(k)];
      if (c < 0) continue;
      const lid_t* lo = &colIdx(0) + rowPtr(r);
      const lid_t* hi = &colIdx(0) + rowPtr(r + 1);
      values(std::lower_bound(lo, hi, c) - &colIdx(0)) -= wk;
    }
  }
  Kokkos::deep_copy(A.values, values);
  return A;
}

void allocateAmg(const ExecSpace& exec, const SmoothingGraph& g, LaplacianCgWork& w) {
  const lid_t n = g.nNodes();
  if (w.amg[0] && static_cast<lid_t>(w.z.extent(0)) == n) return;
  auto fixed = Kokkos::create_mirror_view_and_copy(HostSpace(), g.fixed);
  const bool sliding = g.slideNormal.extent(0) > 0;
  auto sn = Kokkos::create_mirror_view_and_copy(HostSpace(), g.slideNormal);
  w.z = Real3View("mfsi::kernels::laplacianCg::z", n);
  w.rc = RealView("mfsi::kernels::laplacianCg::rComponent", n);
  w.zc = RealView("mfsi::kernels::laplacianCg::zComponent", n);
  for (int c = 0; c < 3; ++c) {
    w.amg[c].reset();
    // Without sliding nodes the three components share one matrix and one hierarchy.
    if (c > 0 && !sliding) {
      w.matrix[c] = w.matrix[0];
      w.freeNodes[c] = w.freeNodes[0];
      w.amg[c] = w.amg[0];
      continue;
    }
    std::vector<lid_t> freeNodes;
    w.matrix[c] = componentLaplacian(
        g, [&](lid_t i) { return fixed(i) != 0 || (sliding && std::abs(sn(i, c)) > 0.5); }, freeNodes);
    const lid_t m = w.matrix[c].nRows;
    w.freeNodes[c] = IndexView("mfsi::kernels::laplacianCg::freeNodes", m);
    auto h = Kokkos::create_mirror_view(w.freeNodes[c]);
    for (lid_t r = 0; r < m; ++r) h(r) = freeNodes[r];
    Kokkos::deep_copy(w.freeNodes[c], h);
    w.amg[c] = std::make_shared<AmgPreconditioner>();
    if (m > 0) w.amg[c]->setup(exec, w.matrix[c]);
  }
}

/// z = P M^{-1} P r with M the AMG cycle of each component on its free nodes and P the projection
/// on the free space (zero at fixed nodes: held in every component, never written; the plane at
/// sliding nodes); returns r . z.
double amgPrecondition(const ExecSpace& exec, const SmoothingGraph& g, LaplacianCgWork& w) {
  const lid_t n = g.nRows();
  const Real3View r = w.r, z = w.z;
  const RealView rc = w.rc, zc = w.zc;
  Kokkos::deep_copy(exec, z, 0.0);
  for (int c = 0; c < 3; ++c) {
    const lid_t m = w.matrix[c].nRows;
    if (m == 0) continue;
    const ConstIndexView node = w.freeNodes[c];
    Kokkos::parallel_for(
        "mfsi::kernels::laplacianCg::component", RangePolicy(exec, 0, m),
        KOKKOS_LAMBDA(lid_t k) { rc(k) = r(node(k), c); });
    w.amg[c]->apply(exec, rc, zc);
    Kokkos::parallel_for(
        "mfsi::kernels::laplacianCg::gather", RangePolicy(exec, 0, m),
        KOKKOS_LAMBDA(lid_t k) { z(node(k), c) = zc(k); });
  }
  const ConstReal3View sn = g.slideNormal;
  const bool sliding = sn.extent(0) > 0;
  return blas::reduce<1>(exec, g.comm, "mfsi::kernels::laplacianCg::project", n,
                         KOKKOS_LAMBDA(lid_t i, blas::Sums<1> & acc) {
                           if (sliding) {
                             const real zn = z(i, 0) * sn(i, 0) + z(i, 1) * sn(i, 1) + z(i, 2) * sn(i, 2);
                             for (int c = 0; c < 3; ++c) z(i, c) -= zn * sn(i, c);
                           }
                           for (int c = 0; c < 3; ++c) acc[0] += r(i, c) * z(i, c);
                         })[0];
}

}  // namespace

LaplacianCgResult laplacianCg(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, LaplacianCgWork& work,
                              const LaplacianCgOptions& options) {
  allocate(work, g.nNodes());
  const lid_t n = g.nRows();
  const bool amg = options.preconditioner == LaplacianPreconditioner::Amg;
  if (amg) allocateAmg(exec, g, work);
  const LaplacianRow row = rowOf(g);
  const auto fixed = g.fixed;
  const Real3View r = work.r, p = work.p, q = work.q;
  const RealView dinv = work.inverseDiagonal;
  const SolverComm& comm = g.comm;
  comm.updateGhosts(exec, d);
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
  const double scale = options.fieldScaled ? std::max(res.initialResidual, std::sqrt(s0[2])) : res.initialResidual;
  const double target = std::max({options.absTol, options.relTol * scale, floor});
  if (!(res.initialResidual > target)) {
    res.converged = true;
    return res;  // d untouched (its ghosts refreshed)
  }
  const Real3View z = work.z;
  if (amg) {
    rz = amgPrecondition(exec, g, work);
    Kokkos::deep_copy(exec, p, z);
  }
  for (int it = 0; it < options.maxIterations; ++it) {
    comm.updateGhosts(exec, p);
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
    const double rzNew = amg ? amgPrecondition(exec, g, work) : s[1];
    const real beta = rzNew / rz;
    rz = rzNew;
    Kokkos::parallel_for(
        "mfsi::kernels::laplacianCg::direction", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
          for (int c = 0; c < 3; ++c) p(i, c) = (amg ? z(i, c) : r(i, c) * dinv(i)) + beta * p(i, c);
        });
  }
  comm.updateGhosts(exec, d);
  return res;
}

}  // namespace mfsi
