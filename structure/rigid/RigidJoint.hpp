#pragma once
/// \file
/// \brief Kinematics of one joint frame: how an elementary axis (Px ... Rz) or a fixed offset moves
/// a frame, propagating position, orientation, velocity and acceleration from parent to child.
#include "core/RigidPlacement.hpp"
#include "structure/rigid/RigidOptions.hpp"

#include <Eigen/Dense>

#include <vector>

namespace mfsi {

/// \brief Motion of a frame in the world: origin, orientation (frame -> world), angular velocity
/// and acceleration, and the velocity and acceleration of the origin. All vectors in world axes.
struct RigidFrameMotion {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();

  /// \brief Velocity of the world point p moving with this frame.
  Eigen::Vector3d pointVelocity(const Eigen::Vector3d& p) const { return velocity + omega.cross(p - origin); }
  /// \brief Acceleration of the world point p moving with this frame.
  Eigen::Vector3d pointAcceleration(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - origin;
    return acceleration + alpha.cross(d) + omega.cross(omega.cross(d));
  }
};

/// \brief The placement that takes a body from its start (centre c0, orientation R0) to now (c,
/// R): x = c + R R0^T (X - c0), the rigid frames' motion in the project's one placement type.
inline RigidPlacement placementFromStart(const Eigen::Vector3d& c0, const Eigen::Matrix3d& R0,
                                         const Eigen::Vector3d& c, const Eigen::Matrix3d& R) {
  RigidPlacement p;
  const Eigen::Matrix3d Q = R * R0.transpose();
  for (int k = 0; k < 3; ++k) {
    p.origin[k] = c0[k];
    p.placed[k] = c[k];
    for (int j = 0; j < 3; ++j) p.rotation[k][j] = Q(k, j);
  }
  return p;
}

/// \brief Rotation by angle about the x (0), y (1) or z (2) axis.
inline Eigen::Matrix3d rigidAxisRotation(int direction, double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(direction)).toRotationMatrix();
}

/// \brief Move a frame rigidly to `offset` (in its own axes) and rotate it by `orientation`.
inline RigidFrameMotion applyRigidOffset(const RigidFrameMotion& f, const Eigen::Vector3d& offset,
                                         const Eigen::Matrix3d& orientation) {
  RigidFrameMotion g = f;
  const Eigen::Vector3d d = f.rotation * offset;
  g.origin = f.origin + d;
  g.velocity = f.pointVelocity(g.origin);
  g.acceleration = f.pointAcceleration(g.origin);
  g.rotation = f.rotation * orientation;
  return g;
}

/// \brief Apply one elementary axis with coordinate q, rate qd and acceleration qdd to a frame.
///
/// Why these terms: a prismatic axis e rotates with the frame, so the child origin o + e q picks
/// up the transport terms alpha x (e q) + omega x (omega x (e q)) and the Coriolis term
/// 2 omega x (e qd); a revolute axis adds e qd to omega and, since e itself turns with omega,
/// omega x (e qd) to alpha.
inline RigidFrameMotion applyRigidAxis(const RigidFrameMotion& f, RigidAxis axis, double q, double qd, double qdd) {
  RigidFrameMotion g = f;
  const int dir = axisDirection(axis);
  const Eigen::Vector3d e = f.rotation.col(dir);
  if (isRevolute(axis)) {
    g.alpha = f.alpha + f.omega.cross(e * qd) + e * qdd;
    g.omega = f.omega + e * qd;
    g.rotation = f.rotation * rigidAxisRotation(dir, q);
  } else {
    const Eigen::Vector3d d = e * q;
    g.origin = f.origin + d;
    g.velocity = f.velocity + f.omega.cross(d) + e * qd;
    g.acceleration =
        f.acceleration + f.alpha.cross(d) + f.omega.cross(f.omega.cross(d)) + 2.0 * f.omega.cross(e * qd) + e * qdd;
  }
  return g;
}

/// \brief The elementary axes of a joint, expanded from its type (Composite/Prescribed: `axes`).
std::vector<RigidAxis> rigidJointAxes(const RigidJointOptions& joint);

}  // namespace mfsi
