#include "kernels/JacobiSmoothing.hpp"

namespace mfsi {

void jacobiSweep(const ExecSpace& exec, const SmoothingGraph& g, const ConstReal3View& in, const Real3View& out) {
  const ConstIndexView off = g.offsets, nb = g.neighbours;
  const auto fixed = g.fixed;
  const ConstRealView w = g.weights;
  const bool weighted = w.extent(0) > 0;
  const ConstReal3View sn = g.slideNormal;
  const bool sliding = sn.extent(0) > 0;
  Kokkos::parallel_for(
      "mfsi::kernels::smoothing::jacobiSweep", RangePolicy(exec, 0, g.nRows()), KOKKOS_LAMBDA(lid_t i) {
        const lid_t k0 = off(i), k1 = off(i + 1);
        if (fixed(i) != 0 || k1 == k0) {
          for (int c = 0; c < 3; ++c) out(i, c) = in(i, c);
          return;
        }
        real s0 = 0, s1 = 0, s2 = 0, ws = 0;
        for (lid_t k = k0; k < k1; ++k) {
          const lid_t j = nb(k);
          const real wk = weighted ? w(k) : real(1);
          s0 += wk * in(j, 0);
          s1 += wk * in(j, 1);
          s2 += wk * in(j, 2);
          ws += wk;
        }
        const real inv = real(1) / ws;
        real m[3] = {s0 * inv - in(i, 0), s1 * inv - in(i, 1), s2 * inv - in(i, 2)};  // the update
        if (sliding) {
          const real dn = m[0] * sn(i, 0) + m[1] * sn(i, 1) + m[2] * sn(i, 2);
          for (int c = 0; c < 3; ++c) m[c] -= dn * sn(i, c);
        }
        for (int c = 0; c < 3; ++c) out(i, c) = in(i, c) + m[c];
      });
  g.comm.updateGhosts(exec, out);
}

void jacobiSmooth(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, const Real3View& work,
                  int sweeps) {
  for (int s = 0; s + 1 < sweeps; s += 2) {
    jacobiSweep(exec, g, d, work);
    jacobiSweep(exec, g, work, d);
  }
  if (sweeps % 2 == 1) {
    jacobiSweep(exec, g, d, work);
    Kokkos::deep_copy(exec, d, work);
  }
}

}  // namespace mfsi
