#pragma once
/// \file
/// \brief The fluid-mesh nodes that move with a rigid body: the nodes of the fluid patches a body
/// carries (`coupling.bodyPatches`), placed by the body's rigid transform.
///
/// The mesh is the body's start configuration: a node at reference position X sits at
///   x = c + R R0^T (X - c0)
/// with (c0, R0) the body's centre of mass and orientation at the start and (c, R) its current
/// ones, so its displacement from the reference is x - X. Written into the mesh motion's
/// prescribed displacements; the interior follows by the point-Laplacian.
#include "core/HexMesh.hpp"
#include "core/RigidPlacement.hpp"

#include <array>
#include <string>
#include <vector>

namespace mfsi::coupling {

class BodyPatchMotion {
 public:
  BodyPatchMotion() = default;
  /// The nodes of every face of `patches` (each must exist; the caller names the key), with their
  /// reference positions (the mesh's points now).
  BodyPatchMotion(const HexMesh& mesh, const std::vector<std::string>& patches);
  /// \brief The same on one rank's part of a decomposed mesh: the nodes of the patches' faces in
  /// the `whole` mesh that the rank holds (owned or ghost, found by global id), whether or not the
  /// rank holds a face of the patch at that node; indices are the part's.
  BodyPatchMotion(const HexMesh& whole, const std::vector<std::string>& patches, const HexMesh& part);

  /// Mesh patches a name stands for: the patch, or both sides of a baffle (<name>_master,
  /// <name>_slave); empty when the mesh has neither.
  static std::vector<int> patchIndices(const HexMesh& mesh, const std::string& name);

  lid_t nNodes() const { return static_cast<lid_t>(nodes_.extent(0)); }
  /// Node indices (host copy, sorted by global id).
  const std::vector<lid_t>& hostNodes() const { return hostNodes_; }

  /// displacement(node) = T.apply(X) - X for this body's nodes; other entries untouched.
  void apply(const ExecSpace& exec, const RigidPlacement& T, const Real3View& displacement) const;

 private:
  IndexView nodes_;
  Real3View reference_;
  std::vector<lid_t> hostNodes_;
};

}  // namespace mfsi::coupling
