#pragma once
// Host <-> device copies of solver vectors (std::vector<double> columns) and a host CSR for gold
// computations in tests.
#include "core/Types.hpp"
#include "kernels/CsrMatrix.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace mfsi::test {

using HostVec = std::vector<double>;

/// Host copy of a device vector.
inline HostVec host(const RealView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return HostVec(h.data(), h.data() + h.extent(0));
}

/// Host copy of a read-only device vector (a solver's field).
inline HostVec host(const ConstRealView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return HostVec(h.data(), h.data() + h.extent(0));
}

/// Column c of a read-only n x 3 device multi-vector (a solver's velocity).
inline HostVec column(const ConstReal3View& v, int c) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  HostVec out(h.extent(0));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = h(i, c);
  return out;
}

/// Device copy of a host vector.
inline RealView device(const HostVec& v) {
  RealView d("test::vec", v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(d, h);
  return d;
}

/// Column c of an n x 3 device multi-vector.
inline HostVec column(const Real3View& v, int c) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  HostVec out(h.extent(0));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = h(i, c);
  return out;
}

/// n x 3 device multi-vector from three host columns.
inline Real3View device3(const std::array<HostVec, 3>& cols) {
  Real3View d("test::vec3", cols[0].size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < cols[0].size(); ++i)
    for (int c = 0; c < 3; ++c) h(i, c) = cols[c][i];
  Kokkos::deep_copy(d, h);
  return d;
}

/// max_i |a_i - b_i| / max_i |b_i|.
inline double relDiff(const HostVec& a, const HostVec& b) {
  double d = 0, s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    d = std::max(d, std::abs(a[i] - b[i]));
    s = std::max(s, std::abs(b[i]));
  }
  return d / s;
}

/// Host copy of a CSR matrix, for gold computations.
struct HostCsr {
  std::vector<lid_t> rowPtr, colIdx;
  HostVec values;
  lid_t n = 0;
  explicit HostCsr(const CsrMatrix& A) : n(A.nRows) {
    auto rp = Kokkos::create_mirror_view_and_copy(HostSpace(), A.rowPtr);
    auto ci = Kokkos::create_mirror_view_and_copy(HostSpace(), A.colIdx);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), A.values);
    rowPtr.assign(rp.data(), rp.data() + rp.extent(0));
    colIdx.assign(ci.data(), ci.data() + ci.extent(0));
    values.assign(v.data(), v.data() + v.extent(0));
  }
  /// A x.
  HostVec apply(const HostVec& x) const {
    HostVec y(n, 0.0);
    for (lid_t i = 0; i < n; ++i)
      for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k) y[i] += values[k] * x[colIdx[k]];
    return y;
  }
  /// |b - A x|_1, recomputed from scratch.
  double residualL1(const HostVec& b, const HostVec& x) const {
    const HostVec ax = apply(x);
    double s = 0;
    for (lid_t i = 0; i < n; ++i) s += std::abs(b[i] - ax[i]);
    return s;
  }
};

}  // namespace mfsi::test
