#pragma once
/// \file
/// \brief Plain option structs and enums of the rigid multi-body frame model (bodies on joints,
/// restraints, Newmark solver). A config layer fills these from YAML; the solver never sees YAML.
///
/// Conventions (shared by every Rigid* file):
///  - Every body has a body frame. Its joint connects it to the parent body's frame (or to the
///    fixed world frame): the joint frame sits at `RigidJointOptions::origin` in the parent frame,
///    rotated by `RigidJointOptions::orientation`; then the joint's elementary axes are applied in
///    order, each in the frame produced by the ones before it (so Px+Py+Rz = move in x, move in y,
///    then turn about the resulting z axis). The frame after the last axis is the body frame.
///  - Centre of mass and inertia (about the CoM) are given in the body frame.
///  - Angles in radians, SI units, gravity is an acceleration vector in the world frame.
#include <Eigen/Dense>

#include <functional>
#include <string>
#include <vector>

namespace mfsi {

/// \brief One-degree-of-freedom elementary joint axis: translation (P) along or rotation (R)
/// about the x, y or z axis of the current joint frame.
enum class RigidAxis { Px, Py, Pz, Rx, Ry, Rz };

/// \brief Kind of joint between a body and its parent.
enum class RigidJointType {
  Fixed,       ///< no freedom (OpenFOAM "null"): the body moves rigidly with its parent
  Px,          ///< prismatic along x
  Py,          ///< prismatic along y
  Pz,          ///< prismatic along z
  Rx,          ///< revolute about x
  Ry,          ///< revolute about y
  Rz,          ///< revolute about z
  Composite,   ///< the sequence `RigidJointOptions::axes`, one free coordinate each
  Prescribed,  ///< the sequence `axes` with each coordinate a given function of time (no freedom)
};

/// \brief Parse "Px", "Py", "Pz", "Rx", "Ry", "Rz" (case-sensitive). Throws InputError otherwise.
RigidAxis parseRigidAxis(const std::string& name);
/// \brief Parse "fixed", "Px" ... "Rz", "composite", "prescribed". Throws InputError otherwise.
RigidJointType parseRigidJointType(const std::string& name);
/// \brief Name of an axis ("Px" ... "Rz").
const char* rigidAxisName(RigidAxis axis);
/// \brief True for Rx, Ry, Rz.
inline bool isRevolute(RigidAxis a) { return a == RigidAxis::Rx || a == RigidAxis::Ry || a == RigidAxis::Rz; }
/// \brief Unit vector (0 = x, 1 = y, 2 = z) of an axis, in the current joint frame.
inline int axisDirection(RigidAxis a) { return static_cast<int>(a) % 3; }

/// \brief A scalar function of time with its first two derivatives.
///
/// `rate` and `acceleration` are optional: when empty they are taken by central differences of
/// `value` with step `fdStep` (error O(fdStep^2)), which is fine for smooth motions.
struct RigidTimeFunction {
  std::function<double(double)> value;
  std::function<double(double)> rate;
  std::function<double(double)> acceleration;
  double fdStep = 1e-4;

  /// \brief The value at t.
  double operator()(double t) const { return value(t); }
  /// \brief d/dt value.
  double derivative(double t) const;
  /// \brief d^2/dt^2 value.
  double secondDerivative(double t) const;
  /// \brief True if a value function is set.
  bool valid() const { return static_cast<bool>(value); }

  /// \brief A constant c.
  static RigidTimeFunction constant(double c);
  /// \brief a + b t (exact derivatives).
  static RigidTimeFunction linear(double a, double b);
  /// \brief offset + amplitude sin(omega t + phase) (exact derivatives).
  static RigidTimeFunction sine(double amplitude, double omega, double phase = 0.0, double offset = 0.0);
};

/// \brief How a body is attached to its parent.
struct RigidJointOptions {
  RigidJointType type = RigidJointType::Fixed;
  /// Composite / Prescribed: the elementary axes in application order. Ignored otherwise.
  std::vector<RigidAxis> axes;
  /// Prescribed: one function per axis giving the coordinate (m or rad) in time.
  std::vector<RigidTimeFunction> motion;
  /// Joint location in the parent body frame (world frame for a root body).
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /// Joint frame orientation relative to the parent frame (columns: joint axes in parent frame).
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();
  /// Initial coordinates and rates, one per free axis (empty = zeros).
  std::vector<double> q0;
  std::vector<double> qdot0;
};

/// \brief One rigid body.
struct RigidBodyOptions {
  std::string name;
  /// Name of the parent body; "" or "world" = fixed world. The parent must be listed earlier.
  std::string parent;
  double mass = 1.0;
  /// Centre of mass in the body frame.
  Eigen::Vector3d centreOfMass = Eigen::Vector3d::Zero();
  /// Inertia tensor about the centre of mass, in the body frame (symmetric positive semi-definite).
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  RigidJointOptions joint;
};

/// \brief Spring (plus axial damper) between a world anchor and a point fixed on a body:
/// F = -(stiffness (L - restLength) + damping dL/dt) e, e the unit vector anchor -> point.
struct RigidLinearSpringOptions {
  std::string name;
  std::string body;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();      ///< world frame
  Eigen::Vector3d attachment = Eigen::Vector3d::Zero();  ///< body frame
  double stiffness = 0.0;
  double damping = 0.0;
  double restLength = 0.0;
};

/// \brief Linear damper on the body's CoM velocity: F = -coefficient v_CoM, applied at the CoM.
struct RigidLinearDamperOptions {
  std::string name;
  std::string body;
  double coefficient = 0.0;
};

/// \brief Angular damper on the body's angular velocity: moment = -coefficient omega.
struct RigidAngularDamperOptions {
  std::string name;
  std::string body;
  double coefficient = 0.0;
};

/// \brief Drive one revolute coordinate of a body's joint along angle(t).
///
/// Implemented as an exact constraint, not a PD law (unlike OpenFOAM's PID `prescribedRotation`):
/// the coordinate is removed from the free set and its acceleration is imposed as
///   qddot = angle'' + 2 zeta w (angle' - qdot) + w^2 (angle - q)
/// evaluated implicitly at the end of the Newmark step, so the error obeys a damped oscillator
/// that the integrator cannot destabilise. The motor torque needed (a joint reaction) is reported
/// by `RigidBodySystem::metrics()` as "restraint.<name>.torque".
struct RigidPrescribedRotationOptions {
  std::string name;
  std::string body;
  /// Index of the axis within the body's joint (must be a free revolute axis); -1 = the first
  /// revolute axis of that joint.
  int axis = -1;
  RigidTimeFunction angle;
  /// Drift-correction frequency w (rad/s); <= 0 picks 0.25 / dt (corrects within a few steps).
  double frequency = 0.0;
  double dampingRatio = 1.0;
};

/// \brief How the implicit Newmark step is solved for the new accelerations.
enum class RigidIteration {
  Newton,      ///< Newton with a finite-difference Jacobian (robust for stiff springs)
  FixedPoint,  ///< qddot <- M^-1 Q(q(qddot)); converges only while beta (omega dt)^2 < 1
};

/// \brief Newmark time integration, OpenFOAM rigidBodyMotion semantics.
struct RigidNewmarkOptions {
  double gamma = 0.5;
  double beta = 0.25;
  /// New acceleration = r * solved + (1 - r) * acceleration of the previous solve call
  /// (previous FSI iteration, or previous time step on the first call of a step).
  double accelerationRelaxation = 1.0;
  /// Factor on the accelerations in the position/velocity update; 0 keeps the velocity at its
  /// old value (a body starting from rest stays frozen).
  double accelerationDamping = 1.0;
  RigidIteration iteration = RigidIteration::Newton;
  int maxIterations = 20;
  /// Converged when max |change of qddot| <= tolerance * (1 + max |qddot|) (SI units).
  double tolerance = 1e-10;
};

/// \brief Everything needed to build a `RigidBodySystem`.
struct RigidSystemOptions {
  std::vector<RigidBodyOptions> bodies;
  std::vector<RigidLinearSpringOptions> linearSprings;
  std::vector<RigidLinearDamperOptions> linearDampers;
  std::vector<RigidAngularDamperOptions> angularDampers;
  std::vector<RigidPrescribedRotationOptions> prescribedRotations;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  RigidNewmarkOptions solver;
  double startTime = 0.0;
};

}  // namespace mfsi
