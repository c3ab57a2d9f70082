#include "core/PointTree.hpp"

#include <algorithm>
#include <limits>

namespace mfsi {

PointTree::PointTree(std::vector<std::array<real, 3>> points) : points_(std::move(points)), axis_(points_.size(), 0) {
  build(0, points_.size(), 0);
}

void PointTree::build(std::size_t lo, std::size_t hi, int depth) {
  if (hi - lo <= 1) return;
  // Split along the widest extent of this node's points, at the median.
  std::array<real, 3> mn{points_[lo]}, mx{points_[lo]};
  for (std::size_t i = lo; i < hi; ++i)
    for (int c = 0; c < 3; ++c) {
      mn[c] = std::min(mn[c], points_[i][c]);
      mx[c] = std::max(mx[c], points_[i][c]);
    }
  int a = 0;
  for (int c = 1; c < 3; ++c)
    if (mx[c] - mn[c] > mx[a] - mn[a]) a = c;
  const std::size_t mid = (lo + hi) / 2;
  std::nth_element(points_.begin() + static_cast<std::ptrdiff_t>(lo), points_.begin() + static_cast<std::ptrdiff_t>(mid),
                   points_.begin() + static_cast<std::ptrdiff_t>(hi),
                   [a](const std::array<real, 3>& p, const std::array<real, 3>& q) { return p[a] < q[a]; });
  axis_[mid] = static_cast<unsigned char>(a);
  build(lo, mid, depth + 1);
  build(mid + 1, hi, depth + 1);
}

void PointTree::search(std::size_t lo, std::size_t hi, const std::array<real, 3>& x, real& best) const {
  if (lo >= hi) return;
  const std::size_t mid = (lo + hi) / 2;
  const auto& p = points_[mid];
  const real dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
  best = std::min(best, dx * dx + dy * dy + dz * dz);
  if (hi - lo == 1) return;
  const int a = axis_[mid];
  const real gap = x[a] - p[a];
  // The side the query lies on first; the other only if the splitting plane is closer than the best.
  if (gap < 0) {
    search(lo, mid, x, best);
    if (gap * gap < best) search(mid + 1, hi, x, best);
  } else {
    search(mid + 1, hi, x, best);
    if (gap * gap < best) search(lo, mid, x, best);
  }
}

real PointTree::nearestSquaredDistance(const std::array<real, 3>& x) const {
  real best = std::numeric_limits<real>::infinity();
  search(0, points_.size(), x, best);
  return best;
}

}  // namespace mfsi
