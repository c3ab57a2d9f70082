#pragma once
/// \file
/// \brief Surface mesh of a membrane: 3D reference node positions, bilinear quadrilaterals and
/// linear triangles (mixed allowed), named node sets, boundary loops and the node -> element map
/// used by every assembly gather. Generators: rectangle (optionally jittered, quads or
/// triangles), disc by an O-grid, annulus.
///
/// Conventions: an element lists its nodes counter-clockwise seen from the side its normal
/// points to (right-hand rule); a triangle stores -1 in slot 3. All elements of a mesh must be
/// oriented consistently (checked), so "positive pressure pushes along the element normal" means
/// the same side everywhere.
#include "core/Types.hpp"
#include "kernels/CsrAssembly.hpp"

#include <array>
#include <map>
#include <string>
#include <vector>

namespace mfsi {

/// Element kinds of a membrane mesh.
enum class MembraneElementType { Quad4, Tri3 };

/// \brief Host description of a membrane mesh (generators and readers fill this).
struct MembraneMeshInput {
  std::string source;  ///< file or generator name, for messages
  std::vector<std::array<real, 3>> points;
  std::vector<std::array<lid_t, 4>> elements;  ///< 4 node ids (quads) or 3 and -1 (triangles)
  std::map<std::string, std::vector<lid_t>> nodeSets;
};

/// \brief A membrane surface mesh. Topology and reference positions are fixed after construction.
class MembraneMesh {
 public:
  MembraneMesh() = default;

  lid_t nNodes() const { return static_cast<lid_t>(hostPoints_.size()); }
  lid_t nElements() const { return static_cast<lid_t>(hostElements_.size()); }
  lid_t nQuads() const { return nQuads_; }
  lid_t nTriangles() const { return nElements() - nQuads_; }

  /// \brief Reference (undeformed) node positions.
  ConstReal3View referencePoints() const { return points_; }
  /// \brief Element nodes (slot 3 is -1 for triangles).
  ConstQuad4View elementNodes() const { return elements_; }
  /// \brief Node -> (element, local node) map (entries element * 4 + local).
  const NodeItemMap& nodeElements() const { return nodeElements_; }
  /// \brief Unit reference normal per node: area-weighted average of the adjacent elements'.
  ConstReal3View nodeNormals() const { return nodeNormals_; }

  const std::vector<std::array<real, 3>>& hostPoints() const { return hostPoints_; }
  const std::vector<std::array<lid_t, 4>>& hostElements() const { return hostElements_; }
  const std::vector<std::array<real, 3>>& hostNodeNormals() const { return hostNormals_; }
  /// \brief Reference area of each element (host).
  const std::vector<real>& elementAreas() const { return elementAreas_; }
  real referenceArea() const { return referenceArea_; }

  /// \brief Nodes on the free edge of the surface (edges used by one element), sorted.
  const std::vector<lid_t>& boundaryNodes() const { return boundaryNodes_; }
  /// \brief Closed boundary loops, each an ordered node list following the element orientation
  /// (first node not repeated at the end).
  const std::vector<std::vector<lid_t>>& boundaryLoops() const { return boundaryLoops_; }

  bool hasNodeSet(const std::string& name) const { return nodeSets_.count(name) > 0; }
  /// \brief A named node set; throws InputError listing the known names when absent.
  const std::vector<lid_t>& nodeSet(const std::string& name) const;
  const std::map<std::string, std::vector<lid_t>>& nodeSets() const { return nodeSets_; }

  /// \brief Node nearest to a point (reference positions).
  lid_t nearestNode(const std::array<real, 3>& p) const;
  /// \brief Node nearest to the area centroid of the reference surface.
  lid_t centreNode() const { return centreNode_; }
  const std::string& source() const { return source_; }

 private:
  friend MembraneMesh buildMembraneMesh(const MembraneMeshInput& in);

  std::string source_;
  lid_t nQuads_ = 0;
  lid_t centreNode_ = 0;
  real referenceArea_ = 0;
  std::vector<std::array<real, 3>> hostPoints_;
  std::vector<std::array<lid_t, 4>> hostElements_;
  std::vector<std::array<real, 3>> hostNormals_;
  std::vector<real> elementAreas_;
  std::vector<lid_t> boundaryNodes_;
  std::vector<std::vector<lid_t>> boundaryLoops_;
  std::map<std::string, std::vector<lid_t>> nodeSets_;
  Real3View points_;
  Quad4View elements_;
  Real3View nodeNormals_;
  NodeItemMap nodeElements_;
};

/// \brief Build the mesh. Adds the node sets "boundary" (all free-edge nodes) and "centre" (the
/// node nearest the area centroid) unless given. Throws InputError (naming the source and the
/// element) for out-of-range or repeated node ids, degenerate elements, edges shared by more
/// than two elements and inconsistently oriented neighbours.
MembraneMesh buildMembraneMesh(const MembraneMeshInput& in);

/// \brief Flat rectangle [x0, x0+lx] x [y0, y0+ly] at z = z0, normal +z.
struct MembraneRectangleSpec {
  std::array<real, 3> origin{0, 0, 0};
  real lx = 1, ly = 1;
  int nx = 4, ny = 4;
  MembraneElementType type = MembraneElementType::Quad4;
  /// Interior nodes moved by a random offset up to jitter x (cell size) per direction (0 = regular),
  /// to make irregular meshes for patch tests. Deterministic for a given seed.
  real jitter = 0;
  unsigned seed = 1;
};

/// \brief Rectangle mesh with node sets "xmin", "xmax", "ymin", "ymax", "corners", "boundary",
/// "centre". Triangles split each cell along alternating diagonals.
MembraneMeshInput generateRectangleMesh(const MembraneRectangleSpec& spec);

/// \brief Flat disc (normal +z) meshed by an O-grid: a core square of nCore x nCore cells whose
/// corners sit at radius coreFraction * radius, and four outer blocks of nCore x nRing cells
/// joining the square to the circle. Node sets "boundary", "centre".
struct MembraneDiscSpec {
  std::array<real, 3> centre{0, 0, 0};
  real radius = 1;
  int nCore = 4;
  int nRing = 4;
  real coreFraction = 0.5;
  /// Ratio of the outermost to the innermost ring cell size (1 = uniform); < 1 refines the rim.
  real ringGrading = 1;
  MembraneElementType type = MembraneElementType::Quad4;
};
MembraneMeshInput generateDiscMesh(const MembraneDiscSpec& spec);

/// \brief Flat annulus innerRadius <= r <= outerRadius (normal +z), nRadial x nTheta quads,
/// radial cell size growing geometrically by `radialGrading` (outer / inner cell). Node sets
/// "inner", "outer", "boundary", "centre".
struct MembraneAnnulusSpec {
  std::array<real, 3> centre{0, 0, 0};
  real innerRadius = 0.2;
  real outerRadius = 1;
  int nRadial = 8;
  int nTheta = 32;
  real radialGrading = 1;
};
MembraneMeshInput generateAnnulusMesh(const MembraneAnnulusSpec& spec);

/// \brief Closed sphere (outward normals) meshed as a cube-sphere: each cube face an n x n grid
/// of quads with equal-angle spacing, projected on the sphere. No boundary. Node set "centre"
/// is the node at the +z pole when n is even.
struct MembraneSphereSpec {
  std::array<real, 3> centre{0, 0, 0};
  real radius = 1;
  int n = 4;
};
MembraneMeshInput generateSphereMesh(const MembraneSphereSpec& spec);

}  // namespace mfsi
