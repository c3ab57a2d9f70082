#include "structure/rigid/RigidJoint.hpp"

#include "core/Error.hpp"

namespace mfsi {

std::vector<RigidAxis> rigidJointAxes(const RigidJointOptions& joint) {
  switch (joint.type) {
    case RigidJointType::Fixed:
      return {};
    case RigidJointType::Px:
      return {RigidAxis::Px};
    case RigidJointType::Py:
      return {RigidAxis::Py};
    case RigidJointType::Pz:
      return {RigidAxis::Pz};
    case RigidJointType::Rx:
      return {RigidAxis::Rx};
    case RigidJointType::Ry:
      return {RigidAxis::Ry};
    case RigidJointType::Rz:
      return {RigidAxis::Rz};
    case RigidJointType::Composite:
    case RigidJointType::Prescribed:
      MFSI_CHECK(!joint.axes.empty(), "composite/prescribed rigid joint needs at least one axis");
      return joint.axes;
  }
  return {};
}

}  // namespace mfsi
