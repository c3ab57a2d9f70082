#include "structure/rigid/RigidRestraint.hpp"

#include "core/Error.hpp"

#include <cmath>

namespace mfsi {

RigidRestraints::RigidRestraints(const RigidBodyModel& model, const RigidSystemOptions& options) {
  for (const auto& s : options.linearSprings) {
    const std::string where = "rigid linearSpring '" + s.name + "'";
    MFSI_CHECK(s.stiffness >= 0 && s.damping >= 0 && s.restLength >= 0,
               where << ": stiffness, damping and restLength must be non-negative");
    springs_.push_back({s, model.bodyIndex(s.body)});
  }
  for (const auto& d : options.linearDampers) {
    MFSI_CHECK(d.coefficient >= 0, "rigid linearDamper '" << d.name << "': coefficient must be non-negative");
    linearDampers_.push_back({d.name, model.bodyIndex(d.body), d.coefficient});
  }
  for (const auto& d : options.angularDampers) {
    MFSI_CHECK(d.coefficient >= 0, "rigid angularDamper '" << d.name << "': coefficient must be non-negative");
    angularDampers_.push_back({d.name, model.bodyIndex(d.body), d.coefficient});
  }
}

RigidRestraints::SpringState RigidRestraints::springState(const Spring& s, const RigidTreeKinematics& kin) const {
  const RigidFrameMotion& f = kin.bodies[s.body].frame;
  SpringState st;
  st.point = f.origin + f.rotation * s.options.attachment;
  st.velocity = f.pointVelocity(st.point);
  const Eigen::Vector3d r = st.point - s.options.anchor;
  st.length = r.norm();
  // A spring of zero length has no direction: it then exerts no force (rest length 0 springs are
  // still fine away from that single point).
  st.direction = st.length > 0 ? Eigen::Vector3d(r / st.length) : Eigen::Vector3d::Zero();
  const double lengthRate = st.velocity.dot(st.direction);
  st.force = s.options.stiffness * (st.length - s.options.restLength) + s.options.damping * lengthRate;
  return st;
}

void RigidRestraints::addLoads(const RigidTreeKinematics& kin, std::vector<RigidBodyLoad>& loads) const {
  for (const auto& s : springs_) {
    const SpringState st = springState(s, kin);
    const Eigen::Vector3d F = -st.force * st.direction;
    loads[s.body].force += F;
    loads[s.body].moment += (st.point - kin.bodies[s.body].com).cross(F);
  }
  for (const auto& d : linearDampers_) loads[d.body].force -= d.coefficient * kin.bodies[d.body].comVelocity;
  for (const auto& d : angularDampers_) loads[d.body].moment -= d.coefficient * kin.bodies[d.body].frame.omega;
}

double RigidRestraints::potentialEnergy(const RigidTreeKinematics& kin) const {
  double e = 0;
  for (const auto& s : springs_) {
    const double stretch = springState(s, kin).length - s.options.restLength;
    e += 0.5 * s.options.stiffness * stretch * stretch;
  }
  return e;
}

void RigidRestraints::addMetrics(const RigidTreeKinematics& kin, std::map<std::string, double>& out) const {
  for (const auto& s : springs_) {
    const SpringState st = springState(s, kin);
    out["restraint." + s.options.name + ".length"] = st.length;
    out["restraint." + s.options.name + ".force"] = st.force;
  }
}

}  // namespace mfsi
