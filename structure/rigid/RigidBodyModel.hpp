#pragma once
/// \file
/// \brief Kinematic tree of rigid bodies on joints: forward kinematics, body Jacobians, the joint-space
/// mass matrix M(q) and generalised forces Q, so that M(q) qddot = Q(t, q, qdot, loads).
///
/// Design: a frame model is a handful of bodies, so the equations are assembled directly from
/// body Jacobians (Kane's method) with dense Eigen algebra instead of Featherstone's recursive
/// spatial-vector algorithms: simpler to verify, and O(n^2) in bodies is irrelevant at this size.
#include "structure/rigid/RigidJoint.hpp"
#include "structure/rigid/RigidOptions.hpp"

#include <Eigen/Dense>

#include <string>
#include <vector>

namespace mfsi {

/// \brief World-frame state of one body: its frame motion plus the centre of mass motion.
struct RigidBodyKinematics {
  RigidFrameMotion frame;                                     ///< body frame (origin at the joint)
  Eigen::Vector3d com = Eigen::Vector3d::Zero();              ///< CoM position (world)
  Eigen::Vector3d comVelocity = Eigen::Vector3d::Zero();      ///< CoM velocity (world)
  Eigen::Vector3d comAcceleration = Eigen::Vector3d::Zero();  ///< CoM acceleration (world)
};

/// \brief Kinematics of the whole tree at one (t, q, qdot, qddot): per body, and per free
/// coordinate its world axis and a point on it (needed for the Jacobians).
struct RigidTreeKinematics {
  std::vector<RigidBodyKinematics> bodies;
  std::vector<Eigen::Vector3d> dofAxis;
  std::vector<Eigen::Vector3d> dofPoint;
};

/// \brief Applied load on one body: total force and moment about the CoM, world axes.
struct RigidBodyLoad {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
};

/// \brief The kinematic tree (no state, no loads): bodies, joints and their coordinates.
class RigidBodyModel {
 public:
  /// \brief Build from body options; parents must precede children. Throws InputError on bad input.
  explicit RigidBodyModel(const std::vector<RigidBodyOptions>& bodies);

  /// \brief Number of bodies.
  int nBodies() const { return static_cast<int>(bodies_.size()); }
  /// \brief Number of free generalised coordinates.
  int nDof() const { return static_cast<int>(dofBody_.size()); }
  /// \brief Index of a body by name; throws InputError listing the known names.
  int bodyIndex(const std::string& name) const;
  /// \brief Name of body b.
  const std::string& bodyName(int b) const { return bodies_[b].name; }
  /// \brief Parent of body b (-1 = world).
  int parent(int b) const { return bodies_[b].parent; }
  /// \brief Mass of body b.
  double mass(int b) const { return bodies_[b].mass; }
  /// \brief CoM of body b in its body frame.
  const Eigen::Vector3d& centreOfMass(int b) const { return bodies_[b].com; }
  /// \brief Inertia of body b about its CoM, body frame.
  const Eigen::Matrix3d& inertia(int b) const { return bodies_[b].inertia; }
  /// \brief Elementary axes of body b's joint.
  const std::vector<RigidAxis>& jointAxes(int b) const { return bodies_[b].axes; }
  /// \brief Free coordinate of axis k of body b's joint, or -1 if that joint is prescribed.
  int axisDof(int b, int k) const { return bodies_[b].prescribed ? -1 : bodies_[b].firstDof + k; }
  /// \brief Body owning free coordinate i.
  int dofBody(int i) const { return dofBody_[i]; }
  /// \brief Elementary axis of free coordinate i.
  RigidAxis dofAxis(int i) const { return dofAxis_[i]; }
  /// \brief True if body a is body b or one of its ancestors.
  bool isAncestorOrSelf(int a, int b) const;

  /// \brief Initial coordinates and rates from the joint options.
  void initialState(Eigen::VectorXd& q, Eigen::VectorXd& qdot) const;

  /// \brief Forward kinematics: world poses, velocities and accelerations of all bodies for free
  /// coordinates (q, qdot, qddot) at time t (time enters through prescribed joints).
  void kinematics(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, const Eigen::VectorXd& qddot,
                  RigidTreeKinematics& out) const;

  /// \brief Body Jacobians: CoM velocity = Jv qdot + (prescribed part), omega = Jw qdot + (...).
  void bodyJacobian(const RigidTreeKinematics& kin, int b, Eigen::MatrixXd& Jv, Eigen::MatrixXd& Jw) const;

  /// \brief Mass matrix and generalised forces from kinematics evaluated with qddot = 0
  /// (so its accelerations are the bias terms) and the applied loads per body:
  ///   M = sum_b m Jv^T Jv + Jw^T I Jw,
  ///   Q = sum_b Jv^T (F - m a_bias) + Jw^T (M_c - I alpha_bias - omega x I omega).
  void equations(const RigidTreeKinematics& biasKin, const std::vector<RigidBodyLoad>& loads, Eigen::MatrixXd& M,
                 Eigen::VectorXd& Q) const;

  /// \brief Point masses m_i at body-frame positions p_i join body b: its mass, centre of mass and
  /// inertia about it become those of the union (a membrane carried by the body).
  void addPointMasses(int b, const std::vector<double>& m, const std::vector<Eigen::Vector3d>& p);

  /// \brief Inertia tensor of body b about its CoM in world axes for the given kinematics.
  Eigen::Matrix3d worldInertia(const RigidTreeKinematics& kin, int b) const;

 private:
  struct Body {
    std::string name;
    int parent = -1;
    double mass = 0;
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jointOrigin = Eigen::Vector3d::Zero();
    Eigen::Matrix3d jointOrientation = Eigen::Matrix3d::Identity();
    std::vector<RigidAxis> axes;
    bool prescribed = false;
    std::vector<RigidTimeFunction> motion;
    int firstDof = 0;
    std::vector<double> q0, qdot0;
  };
  std::vector<Body> bodies_;
  std::vector<int> dofBody_;
  std::vector<RigidAxis> dofAxis_;
};

}  // namespace mfsi
