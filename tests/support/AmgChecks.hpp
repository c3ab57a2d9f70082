#pragma once
// Shared checks of the AMG tests: rough test vectors and the symmetry / positivity of a
// preconditioner (plain CG needs <M u, v> = <u, M v> and <M u, u> > 0).
#include "kernels/Blas.hpp"
#include "kernels/Preconditioner.hpp"
#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mfsi::test {

/// A rough vector (all frequencies present), optionally shifted to zero mean (Neumann problems).
/// `kind` 0 and 1 give two different ones.
inline RealView roughVector(lid_t n, bool zeroMean, int kind = 0) {
  RealView b("test::rough", n);
  auto h = Kokkos::create_mirror_view(b);
  double s = 0;
  for (lid_t i = 0; i < n; ++i)
    s += (h(i) = kind == 0 ? std::sin(0.7 * i) + std::cos(0.013 * i * i) + 0.3
                           : std::cos(1.3 * i) - 0.2 * std::sin(0.021 * i * i));
  if (zeroMean)
    for (lid_t i = 0; i < n; ++i) h(i) -= s / n;
  Kokkos::deep_copy(b, h);
  return b;
}

/// A fixed pseudo-random permutation of 0..n-1 (Fisher-Yates on a linear congruential sequence
/// started at `seed`): renumbers model matrices so that rows share no column pattern.
inline std::vector<lid_t> randomPermutation(lid_t n, std::uint32_t seed) {
  std::vector<lid_t> perm(n);
  for (lid_t i = 0; i < n; ++i) perm[i] = i;
  std::uint32_t state = seed;
  for (lid_t i = n - 1; i > 0; --i) {
    state = state * 1664525u + 1013904223u;
    std::swap(perm[i], perm[static_cast<lid_t>(state % static_cast<std::uint32_t>(i + 1))]);
  }
  return perm;
}

/// <M u, v> = <u, M v> to `rel` (relative to sqrt(<Mu,u><Mv,v>)) and <M u, u>, <M v, v> > 0 for
/// the two rough vectors of size n (zero-mean ones when `zeroMean`).
inline void expectSymmetricPositive(Preconditioner& M, lid_t n, bool zeroMean, double rel, const std::string& what) {
  const ExecSpace exec;
  const SolverComm comm;
  const RealView u = roughVector(n, zeroMean, 0), v = roughVector(n, zeroMean, 1);
  RealView mu("test::mu", n), mv("test::mv", n);
  M.apply(exec, u, mu);
  M.apply(exec, v, mv);
  const double muv = blas::dot(exec, comm, n, mu, v), umv = blas::dot(exec, comm, n, u, mv);
  const double muu = blas::dot(exec, comm, n, mu, u), mvv = blas::dot(exec, comm, n, mv, v);
  EXPECT_TRUE(near(muv, umv, Tol{0, rel * std::sqrt(muu * mvv)}, what + " <Mu,v> vs <u,Mv>"));
  EXPECT_GT(muu, 0.0) << what;
  EXPECT_GT(mvv, 0.0) << what;
}

}  // namespace mfsi::test
