#pragma once
/// \file
/// \brief Force-type restraints of the rigid multi-body model (OpenFOAM rigidBodyDynamics
/// "restraints"): linear springs with axial damping to a world anchor, linear and angular dampers.
/// They turn the current kinematics into body loads. (Prescribed rotations are constraints and are
/// handled by `RigidBodySystem`.)
#include "structure/rigid/RigidBodyModel.hpp"
#include "structure/rigid/RigidOptions.hpp"

#include <map>
#include <string>
#include <vector>

namespace mfsi {

/// \brief The set of force restraints of a system, resolved against a model's body names.
class RigidRestraints {
 public:
  /// \brief Validate options and resolve body names. Throws InputError on bad input.
  RigidRestraints(const RigidBodyModel& model, const RigidSystemOptions& options);

  /// \brief Add every restraint's force and moment about the CoM to `loads` (one per body).
  void addLoads(const RigidTreeKinematics& kin, std::vector<RigidBodyLoad>& loads) const;

  /// \brief Elastic energy stored in the springs.
  double potentialEnergy(const RigidTreeKinematics& kin) const;

  /// \brief Per-restraint report values, e.g. "restraint.<name>.length" and ".force".
  void addMetrics(const RigidTreeKinematics& kin, std::map<std::string, double>& out) const;

 private:
  struct Spring {
    RigidLinearSpringOptions options;
    int body = -1;
  };
  struct Damper {
    std::string name;
    int body = -1;
    double coefficient = 0;
  };
  /// Spring state: attachment point (world), its velocity, unit vector anchor -> point, length.
  struct SpringState {
    Eigen::Vector3d point, velocity, direction;
    double length = 0;
    double force = 0;  ///< tension (positive pulls the point towards the anchor)
  };
  SpringState springState(const Spring& s, const RigidTreeKinematics& kin) const;

  std::vector<Spring> springs_;
  std::vector<Damper> linearDampers_;
  std::vector<Damper> angularDampers_;
};

}  // namespace mfsi
