#include "structure/rigid/RigidBodyModel.hpp"

#include "core/Error.hpp"

#include <cmath>
#include <sstream>

namespace mfsi {

namespace {
bool isWorld(const std::string& name) { return name.empty() || name == "world"; }
}  // namespace

RigidBodyModel::RigidBodyModel(const std::vector<RigidBodyOptions>& bodies) {
  MFSI_CHECK(!bodies.empty(), "rigid body system: no bodies");
  for (const auto& o : bodies) {
    const std::string where = "rigid body '" + o.name + "'";
    MFSI_CHECK(!o.name.empty() && !isWorld(o.name), "rigid body: every body needs a name other than 'world'");
    for (const auto& b : bodies_) MFSI_CHECK(b.name != o.name, where << ": duplicate body name");
    MFSI_CHECK(o.mass > 0 && std::isfinite(o.mass), where << ": mass must be positive, got " << o.mass);
    MFSI_CHECK(o.inertia.allFinite() && (o.inertia - o.inertia.transpose()).norm() <= 1e-12 * (1 + o.inertia.norm()),
               where << ": inertia tensor must be symmetric");
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(o.inertia);
    MFSI_CHECK(eig.eigenvalues().minCoeff() >= -1e-12 * (1 + o.inertia.norm()),
               where << ": inertia tensor must be positive semi-definite");
    const Eigen::Matrix3d& Rj = o.joint.orientation;
    MFSI_CHECK((Rj.transpose() * Rj - Eigen::Matrix3d::Identity()).norm() < 1e-9 && Rj.determinant() > 0,
               where << ": joint orientation must be a rotation matrix");

    Body b;
    b.name = o.name;
    if (!isWorld(o.parent)) {
      b.parent = -1;
      for (std::size_t i = 0; i < bodies_.size(); ++i) {
        if (bodies_[i].name == o.parent) b.parent = static_cast<int>(i);
      }
      MFSI_CHECK(b.parent >= 0, where << ": parent '" << o.parent << "' is not a body listed before it");
    }
    b.mass = o.mass;
    b.com = o.centreOfMass;
    b.inertia = o.inertia;
    b.jointOrigin = o.joint.origin;
    b.jointOrientation = Rj;
    b.axes = rigidJointAxes(o.joint);
    b.prescribed = o.joint.type == RigidJointType::Prescribed;
    const std::size_t nAxes = b.axes.size();
    if (b.prescribed) {
      MFSI_CHECK(o.joint.motion.size() == nAxes, where << ": prescribed joint needs one motion function per axis ("
                                                       << nAxes << "), got " << o.joint.motion.size());
      for (const auto& f : o.joint.motion) MFSI_CHECK(f.valid(), where << ": empty prescribed motion function");
      b.motion = o.joint.motion;
    } else {
      MFSI_CHECK(o.joint.q0.empty() || o.joint.q0.size() == nAxes,
                 where << ": joint q0 needs " << nAxes << " values, got " << o.joint.q0.size());
      MFSI_CHECK(o.joint.qdot0.empty() || o.joint.qdot0.size() == nAxes,
                 where << ": joint qdot0 needs " << nAxes << " values, got " << o.joint.qdot0.size());
      b.q0 = o.joint.q0.empty() ? std::vector<double>(nAxes, 0.0) : o.joint.q0;
      b.qdot0 = o.joint.qdot0.empty() ? std::vector<double>(nAxes, 0.0) : o.joint.qdot0;
      b.firstDof = static_cast<int>(dofBody_.size());
      for (RigidAxis a : b.axes) {
        dofBody_.push_back(static_cast<int>(bodies_.size()));
        dofAxis_.push_back(a);
      }
    }
    bodies_.push_back(std::move(b));
  }
}

int RigidBodyModel::bodyIndex(const std::string& name) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].name == name) return static_cast<int>(i);
  }
  std::ostringstream known;
  for (const auto& b : bodies_) known << " '" << b.name << "'";
  MFSI_CHECK(false, "unknown rigid body '" << name << "' (known:" << known.str() << ")");
  return -1;
}

bool RigidBodyModel::isAncestorOrSelf(int a, int b) const {
  for (int c = b; c >= 0; c = bodies_[c].parent) {
    if (c == a) return true;
  }
  return false;
}

void RigidBodyModel::initialState(Eigen::VectorXd& q, Eigen::VectorXd& qdot) const {
  q.setZero(nDof());
  qdot.setZero(nDof());
  for (const auto& b : bodies_) {
    if (b.prescribed) continue;
    for (std::size_t k = 0; k < b.axes.size(); ++k) {
      q[b.firstDof + static_cast<int>(k)] = b.q0[k];
      qdot[b.firstDof + static_cast<int>(k)] = b.qdot0[k];
    }
  }
}

void RigidBodyModel::kinematics(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                                const Eigen::VectorXd& qddot, RigidTreeKinematics& out) const {
  MFSI_ASSERT(q.size() == nDof() && qdot.size() == nDof() && qddot.size() == nDof(), "coordinate size mismatch");
  out.bodies.resize(bodies_.size());
  out.dofAxis.resize(nDof());
  out.dofPoint.resize(nDof());
  // Bodies are ordered parents first, so one forward sweep propagates the motion down the tree.
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    const RigidFrameMotion parentFrame = b.parent < 0 ? RigidFrameMotion{} : out.bodies[b.parent].frame;
    RigidFrameMotion f = applyRigidOffset(parentFrame, b.jointOrigin, b.jointOrientation);
    for (std::size_t k = 0; k < b.axes.size(); ++k) {
      double qk, qdk, qddk;
      if (b.prescribed) {
        qk = b.motion[k](t);
        qdk = b.motion[k].derivative(t);
        qddk = b.motion[k].secondDerivative(t);
      } else {
        const int d = b.firstDof + static_cast<int>(k);
        qk = q[d];
        qdk = qdot[d];
        qddk = qddot[d];
        out.dofAxis[d] = f.rotation.col(axisDirection(b.axes[k]));
        out.dofPoint[d] = f.origin;
      }
      f = applyRigidAxis(f, b.axes[k], qk, qdk, qddk);
    }
    RigidBodyKinematics& k = out.bodies[i];
    k.frame = f;
    k.com = f.origin + f.rotation * b.com;
    k.comVelocity = f.pointVelocity(k.com);
    k.comAcceleration = f.pointAcceleration(k.com);
  }
}

void RigidBodyModel::bodyJacobian(const RigidTreeKinematics& kin, int b, Eigen::MatrixXd& Jv,
                                  Eigen::MatrixXd& Jw) const {
  Jv.setZero(3, nDof());
  Jw.setZero(3, nDof());
  const Eigen::Vector3d& c = kin.bodies[b].com;
  for (int a = b; a >= 0; a = bodies_[a].parent) {
    const Body& body = bodies_[a];
    if (body.prescribed) continue;
    for (std::size_t k = 0; k < body.axes.size(); ++k) {
      const int d = body.firstDof + static_cast<int>(k);
      const Eigen::Vector3d& e = kin.dofAxis[d];
      if (isRevolute(body.axes[k])) {
        Jw.col(d) = e;
        Jv.col(d) = e.cross(c - kin.dofPoint[d]);
      } else {
        Jv.col(d) = e;
      }
    }
  }
}

Eigen::Matrix3d RigidBodyModel::worldInertia(const RigidTreeKinematics& kin, int b) const {
  const Eigen::Matrix3d& R = kin.bodies[b].frame.rotation;
  return R * bodies_[b].inertia * R.transpose();
}

void RigidBodyModel::equations(const RigidTreeKinematics& biasKin, const std::vector<RigidBodyLoad>& loads,
                               Eigen::MatrixXd& M, Eigen::VectorXd& Q) const {
  const int n = nDof();
  M.setZero(n, n);
  Q.setZero(n);
  Eigen::MatrixXd Jv, Jw;
  for (int b = 0; b < nBodies(); ++b) {
    bodyJacobian(biasKin, b, Jv, Jw);
    const RigidBodyKinematics& k = biasKin.bodies[b];
    const Eigen::Matrix3d I = worldInertia(biasKin, b);
    const double m = bodies_[b].mass;
    M.noalias() += m * Jv.transpose() * Jv + Jw.transpose() * I * Jw;
    // Kane: project the Newton-Euler residual with qddot = 0 on the partial velocities.
    const Eigen::Vector3d w = k.frame.omega;
    const Eigen::Vector3d linear = loads[b].force - m * k.comAcceleration;
    const Eigen::Vector3d angular = loads[b].moment - I * k.frame.alpha - w.cross(I * w);
    Q.noalias() += Jv.transpose() * linear + Jw.transpose() * angular;
  }
}

void RigidBodyModel::addPointMasses(int b, const std::vector<double>& m, const std::vector<Eigen::Vector3d>& p) {
  MFSI_CHECK(b >= 0 && b < nBodies() && m.size() == p.size(), "rigid model: addPointMasses: bad arguments");
  Body& body = bodies_[b];
  double M = body.mass;
  Eigen::Vector3d first = body.mass * body.com;
  for (std::size_t i = 0; i < m.size(); ++i) {
    MFSI_CHECK(std::isfinite(m[i]) && m[i] >= 0, "rigid model: a point mass must be finite and >= 0");
    M += m[i];
    first += m[i] * p[i];
  }
  if (!(M > 0)) return;
  const Eigen::Vector3d c = first / M;
  // Parallel axis: a mass at offset r from the new centre adds m (|r|^2 1 - r r^T).
  auto shift = [](double mass, const Eigen::Vector3d& r) {
    return mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  };
  Eigen::Matrix3d I = body.inertia + shift(body.mass, body.com - c);
  for (std::size_t i = 0; i < m.size(); ++i) I += shift(m[i], p[i] - c);
  body.mass = M;
  body.com = c;
  body.inertia = I;
}

}  // namespace mfsi
