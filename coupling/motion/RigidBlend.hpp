#pragma once
/// \file
/// \brief The distance-weighted rigid part of the interior mesh motion (the seed's section 3.2):
/// each coupled rigid body carries the mesh near it rigidly, a share w(d) of its motion that is 1
/// within `innerDistance` of the body's patches, 0 beyond `outerDistance` and
/// (1 + cos(pi (d - inner) / (outer - inner))) / 2 in between (d: distance to the nearest node of
/// the body's patches, on the reference mesh).
///
/// A node's share of a body's motion follows the motion's screw instead of blending positions:
/// the rotation by w times the body's rotation angle about the same axis (the slerp of the
/// identity and the body's rotation) about the body's reference centre, plus w times the centre's
/// translation. A blend of positions would shrink a turned region towards the centre (half of a
/// 180-degree turn would put every node on the axis). Where several bodies reach a node their
/// shares add, scaled down so that the weights sum to at most 1.
///
/// The mesh motion adds this field to the displacement it smooths (MeshSmoother::setBase): the
/// Laplacian then carries only what the rigid part leaves (a membrane's deformation, a wall's
/// hold), so cells next to a turning body turn with it instead of shearing.
#include "core/HexMesh.hpp"
#include "core/RigidPlacement.hpp"

#include <array>
#include <vector>

namespace mfsi::coupling {

class RigidBlend {
 public:
  /// \brief One body: the reference positions of the nodes it carries (its patches', on every
  /// rank: BodyPatchMotion::allReferencePoints) and its two distances [m].
  struct Body {
    std::vector<std::array<real, 3>> points;
    double innerDistance = 0;
    double outerDistance = 0;
  };

  RigidBlend() = default;
  /// The weights of `mesh`'s nodes (a rank's part or the whole mesh), from each node's distance to
  /// the nearest of each body's points, on the reference mesh.
  RigidBlend(const std::vector<Body>& bodies, const HexMesh& mesh);

  /// Straight distance of every node of `mesh` (reference positions) to the nearest of `sources`
  /// (a k-d tree; host).
  static std::vector<double> nearestDistance(const HexMesh& mesh, const std::vector<std::array<real, 3>>& sources);

  /// w(d) of the class comment.
  static double weight(double distance, double inner, double outer);

  bool empty() const { return nBodies_ == 0; }
  int nBodies() const { return nBodies_; }
  /// Weight of body b at node v of the part (host), before the scaling of overlapping bodies.
  double weight(lid_t v, int b) const { return hostWeights_[static_cast<std::size_t>(v) * nBodies_ + b]; }

  /// base(v) = the node's share of the bodies' motions (transforms, one per body, in the order of
  /// the constructor's bodies: x = placed + R (X - origin)), as a displacement from the reference
  /// mesh, for every node of the part. One kernel; no fence.
  void displacement(const ExecSpace& exec, const std::vector<RigidPlacement>& transforms, const Real3View& base) const;

 private:
  Kokkos::View<real**, MemSpace> weights_;  ///< node x body
  std::vector<real> hostWeights_;
  ConstReal3View reference_;
  Kokkos::View<real* [10], MemSpace> screws_;  ///< per body: origin (3), translation (3), unit axis (3), angle
  int nBodies_ = 0;
};

}  // namespace mfsi::coupling
