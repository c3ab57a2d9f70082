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
#include "core/parallel/Halo.hpp"

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
  /// \brief The same on one rank's part of a decomposed mesh (`domain` distributed): every node
  /// the rank holds (owned or ghost) that is a node of a face of the patches on any rank, whether
  /// or not the rank holds such a face. Collective.
  BodyPatchMotion(const HexMesh& mesh, const std::vector<std::string>& patches, const RankDomain& domain);

  /// Mesh patches a name stands for: the patch, or both sides of a baffle (<name>_master,
  /// <name>_slave); empty when the mesh has neither.
  static std::vector<int> patchIndices(const HexMesh& mesh, const std::string& name);

  lid_t nNodes() const { return static_cast<lid_t>(nodes_.extent(0)); }
  /// Node indices (host copy, sorted by global id).
  const std::vector<lid_t>& hostNodes() const { return hostNodes_; }
  /// \brief The reference positions of all the patches' nodes, on every rank's part together,
  /// in global-id order: the same list on every rank and on one rank. Collective on several.
  std::vector<std::array<real, 3>> allReferencePoints() const;

  /// displacement(node) = T.apply(X) - X for this body's nodes; other entries untouched.
  void apply(const ExecSpace& exec, const RigidPlacement& T, const Real3View& displacement) const;

 private:
  IndexView nodes_;
  Real3View reference_;
  std::vector<lid_t> hostNodes_;
  std::vector<gid_t> globalIds_;  ///< of hostNodes_
  lid_t owned_ = 0;               ///< the mesh's owned nodes: [0, owned_)
  MPI_Comm comm_ = MPI_COMM_NULL;
};

}  // namespace mfsi::coupling
