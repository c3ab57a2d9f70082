#include "core/RigidPlacement.hpp"

#include "core/Error.hpp"

#include <cmath>

namespace mfsi {

std::array<real, 3> RigidPlacement::apply(const std::array<real, 3>& X) const {
  std::array<real, 3> x{};
  for (int i = 0; i < 3; ++i) {
    x[i] = placed[i];
    for (int j = 0; j < 3; ++j) x[i] += rotation[i][j] * (X[j] - origin[j]);
  }
  return x;
}

std::array<real, 15> RigidPlacement::flat() const {
  std::array<real, 15> f{};
  for (int k = 0; k < 3; ++k) {
    f[k] = origin[k];
    f[3 + k] = placed[k];
    for (int j = 0; j < 3; ++j) f[6 + 3 * k + j] = rotation[k][j];
  }
  return f;
}

RigidPlacement RigidPlacement::fromFlat(const real* f) {
  RigidPlacement p;
  for (int k = 0; k < 3; ++k) {
    p.origin[k] = f[k];
    p.placed[k] = f[3 + k];
    for (int j = 0; j < 3; ++j) p.rotation[k][j] = f[6 + 3 * k + j];
  }
  return p;
}

RigidPlacement RigidPlacement::rotationAbout(const std::array<real, 3>& axis, real angle,
                                             const std::array<real, 3>& origin) {
  const real l = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  MFSI_CHECK(l > 0, "rotation axis must be non-zero");
  const real k[3] = {axis[0] / l, axis[1] / l, axis[2] / l};
  const real c = std::cos(angle), s = std::sin(angle);
  RigidPlacement t;
  t.origin = origin;
  t.placed = origin;
  // Rodrigues: R = c I + s [k]x + (1 - c) k k^T.
  const real K[3][3] = {{0, -k[2], k[1]}, {k[2], 0, -k[0]}, {-k[1], k[0], 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.rotation[i][j] = (i == j ? c : 0) + s * K[i][j] + (1 - c) * k[i] * k[j];
  return t;
}

}  // namespace mfsi
