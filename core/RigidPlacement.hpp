#pragma once
/// \file
/// \brief The one rigid placement type shared by membranes (clamps on moving frames), rigid
/// bodies (their motion from the start, structure/rigid/RigidJoint.hpp converts) and the mesh
/// motion (body patches, membranes mounted on frames): x = placed + R (X - origin), `placed` being
/// where the reference point `origin` goes.
/// Host-side value; kernels copy its numbers (`flat`).
#include "core/Types.hpp"

#include <array>

namespace mfsi {

struct RigidPlacement {
  std::array<std::array<real, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<real, 3> origin{0, 0, 0};
  std::array<real, 3> placed{0, 0, 0};

  /// \brief The placed position of the reference point X.
  std::array<real, 3> apply(const std::array<real, 3>& X) const;
  /// \brief origin (3), placed (3), rotation row by row (9): what a kernel needs, and a
  /// checkpoint's record (`fromFlat` restores it exactly).
  std::array<real, 15> flat() const;
  static RigidPlacement fromFlat(const real* f);
  /// \brief Rotation by `angle` (rad) about the unit `axis` through `origin`.
  static RigidPlacement rotationAbout(const std::array<real, 3>& axis, real angle, const std::array<real, 3>& origin);
};

}  // namespace mfsi
