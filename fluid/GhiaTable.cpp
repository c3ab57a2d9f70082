#include "fluid/GhiaTable.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace mfsi::fluid {

namespace {

// Source: Ghia, Ghia & Shin, J. Comput. Phys. 48 (1982) 387-411, tables I and II (Re = 100);
// copied from tests/data/ghia1982_re100.csv.
const std::vector<GhiaPoint> kGhiaRe100 = {
    {true, 0.0000, 0.00000},   {true, 0.0547, -0.03717},  {true, 0.0625, -0.04192},  {true, 0.0703, -0.04775},
    {true, 0.1016, -0.06434},  {true, 0.1719, -0.10150},  {true, 0.2813, -0.15662},  {true, 0.4531, -0.21090},
    {true, 0.5000, -0.20581},  {true, 0.6172, -0.13641},  {true, 0.7344, 0.00332},   {true, 0.8516, 0.23151},
    {true, 0.9531, 0.68717},   {true, 0.9609, 0.73722},   {true, 0.9688, 0.78871},   {true, 0.9766, 0.84123},
    {true, 1.0000, 1.00000},   {false, 0.0000, 0.00000},  {false, 0.0625, 0.09233},  {false, 0.0703, 0.10091},
    {false, 0.0781, 0.10890},  {false, 0.0938, 0.12317},  {false, 0.1563, 0.16077},  {false, 0.2266, 0.17507},
    {false, 0.2344, 0.17527},  {false, 0.5000, 0.05454},  {false, 0.8047, -0.24533}, {false, 0.8594, -0.22445},
    {false, 0.9063, -0.16914}, {false, 0.9453, -0.10313}, {false, 0.9531, -0.08864}, {false, 0.9609, -0.07391},
    {false, 0.9688, -0.05906}, {false, 1.0000, 0.00000},
};

// Cubic Lagrange interpolation through the 4 samples nearest to s (x sorted ascending, >= 4 samples).
double interpCubic(const std::vector<double>& x, const std::vector<double>& y, double s) {
  std::size_t k = 0;
  while (k + 1 < x.size() && x[k + 1] < s) ++k;
  std::size_t i0 = k >= 1 ? k - 1 : 0;
  if (i0 + 4 > x.size()) i0 = x.size() - 4;
  double r = 0;
  for (std::size_t a = i0; a < i0 + 4; ++a) {
    double l = 1;
    for (std::size_t b = i0; b < i0 + 4; ++b)
      if (b != a) l *= (s - x[b]) / (x[a] - x[b]);
    r += l * y[a];
  }
  return r;
}

// Linear interpolation between the two samples around s (x sorted ascending, >= 2 samples).
double interpLinear(const std::vector<double>& x, const std::vector<double>& y, double s) {
  std::size_t k = 0;
  while (k + 2 < x.size() && x[k + 1] < s) ++k;
  const double w = (s - x[k]) / (x[k + 1] - x[k]);
  return (1 - w) * y[k] + w * y[k + 1];
}

// Profile of velocity component `comp` along the centreline `lineAxis` (the line sits at the middle
// of `crossAxis`): one sample per cell row, interpolated linearly across the line between the
// nearest centroids on either side. Rows are cells with equal `lineAxis` centroid coordinate.
template <class CView, class UView>
void centreline(const CView& C, const UView& U, int lineAxis, int crossAxis, int comp, double mid, double tol,
                std::vector<double>& pos, std::vector<double>& val) {
  std::map<long long, std::vector<int>> rows;  // keyed by the rounded row coordinate
  for (int c = 0; c < static_cast<int>(C.extent(0)); ++c) rows[std::llround(C(c, lineAxis) / tol)].push_back(c);
  for (const auto& [key, cells] : rows) {
    int lo = -1, hi = -1;
    for (int c : cells) {
      const double d = C(c, crossAxis) - mid;
      if (d <= 0 && (lo < 0 || d > C(lo, crossAxis) - mid)) lo = c;
      if (d >= 0 && (hi < 0 || d < C(hi, crossAxis) - mid)) hi = c;
    }
    if (lo < 0 || hi < 0) continue;
    const double xl = C(lo, crossAxis), xh = C(hi, crossAxis);
    const double w = xh > xl ? (mid - xl) / (xh - xl) : 0.5;
    double p = 0;
    for (int c : cells) p += C(c, lineAxis);
    pos.push_back(p / static_cast<double>(cells.size()));
    val.push_back((1 - w) * U(lo, comp) + w * U(hi, comp));
  }
}

}  // namespace

std::vector<int> ghiaReynoldsNumbers() { return {100}; }

const std::vector<GhiaPoint>& ghiaTable(int re) {
  static const std::vector<GhiaPoint> none;
  return re == 100 ? kGhiaRe100 : none;
}

void planeExtent(const HexMesh& mesh, std::array<double, 2>& lo, std::array<double, 2>& hi) {
  auto P = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  lo = {1e300, 1e300};
  hi = {-1e300, -1e300};
  for (int n = 0; n < static_cast<int>(P.extent(0)); ++n)
    for (int d = 0; d < 2; ++d) {
      lo[d] = std::min(lo[d], P(n, d));
      hi[d] = std::max(hi[d], P(n, d));
    }
}

GhiaErrors ghiaErrors(const FluidSolver& fluid, int re, double lidSpeed) {
  std::array<double, 2> lo, hi;
  planeExtent(fluid.mesh(), lo, hi);
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  auto U = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.velocity());
  const std::size_t n = C.extent(0);
  std::vector<double> c(3 * n), u(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      c[3 * i + k] = C(i, k);
      u[3 * i + k] = U(i, k);
    }
  return ghiaErrors(c, u, lo, hi, re, lidSpeed);
}

GhiaErrors ghiaErrors(const std::vector<double>& centroids, const std::vector<double>& velocity,
                      const std::array<double, 2>& lo, const std::array<double, 2>& hi, int re, double lidSpeed) {
  const auto& table = ghiaTable(re);
  MFSI_CHECK(!table.empty(), "no Ghia table for Re = " << re);
  MFSI_CHECK(centroids.size() == velocity.size() && centroids.size() % 3 == 0, "Ghia comparison: bad field sizes");
  const Kokkos::View<const double**, Kokkos::LayoutRight, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> C(
      centroids.data(), centroids.size() / 3, 3),
      U(velocity.data(), velocity.size() / 3, 3);
  const double Lx = hi[0] - lo[0], Ly = hi[1] - lo[1];
  const double tol = 1e-9 * std::max(Lx, Ly);
  // u on the vertical centreline vs y, v on the horizontal centreline vs x, both normalised.
  std::vector<double> ys, us, xs, vs;
  centreline(C, U, 1, 0, 0, 0.5 * (lo[0] + hi[0]), tol, ys, us);
  centreline(C, U, 0, 1, 1, 0.5 * (lo[1] + hi[1]), tol, xs, vs);
  MFSI_CHECK(ys.size() >= 2 && xs.size() >= 2, "Ghia comparison: the mesh has too few cell rows on the centrelines");
  std::vector<double> y{0.0}, u{0.0}, x{0.0}, v{0.0};
  for (std::size_t i = 0; i < ys.size(); ++i) {
    y.push_back((ys[i] - lo[1]) / Ly);
    u.push_back(us[i] / lidSpeed);
  }
  for (std::size_t i = 0; i < xs.size(); ++i) {
    x.push_back((xs[i] - lo[0]) / Lx);
    v.push_back(vs[i] / lidSpeed);
  }
  y.push_back(1.0);
  u.push_back(1.0);
  x.push_back(1.0);
  v.push_back(0.0);
  GhiaErrors e;
  for (int i = 0; i <= 10000; ++i) {
    const double t = 1e-4 * i;
    e.uLineMin = std::min(e.uLineMin, interpCubic(y, u, t));
    e.vLineMin = std::min(e.vLineMin, interpCubic(x, v, t));
    e.vLineMax = std::max(e.vLineMax, interpCubic(x, v, t));
  }
  for (const auto& g : table) {
    if (g.uLine) {
      e.uMax = std::max(e.uMax, std::abs(interpCubic(y, u, g.coord) - g.value));
      e.uMaxLinear = std::max(e.uMaxLinear, std::abs(interpLinear(y, u, g.coord) - g.value));
    } else {
      e.vMax = std::max(e.vMax, std::abs(interpCubic(x, v, g.coord) - g.value));
      e.vMaxLinear = std::max(e.vMaxLinear, std::abs(interpLinear(x, v, g.coord) - g.value));
    }
  }
  return e;
}

}  // namespace mfsi::fluid
