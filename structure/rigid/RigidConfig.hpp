#pragma once
/// \file
/// \brief Config layer of the `bodies` section: its schema, and the `RigidSystemOptions` it
/// describes. The rigid solver never sees the scene.
///
/// \code{.yaml}
/// bodies:
///   gravity: [0, -9.81, 0]
///   newmark: {gamma: 0.5, beta: 0.25, accelerationRelaxation: 1, accelerationDamping: 1}
///   members:                       # listed parent first
///     arm:
///       mass: 1.0
///       centreOfMass: [0, -0.5, 0]
///       inertia: [0.01, 0.01, 0.01, 0, 0, 0]   # Ixx Iyy Izz Ixy Ixz Iyz about the CoM
///       joint: {type: Rz, origin: [0, 0, 0], q0: [0.1]}
///   restraints:
///     spring: {type: linearSpring, body: arm, anchor: [0, -2, 0], attachment: [0, -1, 0], stiffness: 100}
/// \endcode
#include "core/SceneConfig.hpp"
#include "structure/rigid/RigidOptions.hpp"

namespace mfsi {

/// Schema of the `bodies` section.
Schema rigidSchema();

/// Options described by a view of the `bodies` section. Throws InputError naming the key on
/// semantic errors (unknown body, axes/q0 counts that do not match the joint).
RigidSystemOptions readRigidOptions(const SceneConfig& bodies);

}  // namespace mfsi
