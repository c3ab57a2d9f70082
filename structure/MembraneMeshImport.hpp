#pragma once
/// \file
/// \brief Membrane surfaces that do not come from a generator: the master side of a baffle of
/// the fluid mesh (with the membrane node -> fluid node map the coupling needs), and Gmsh 4.1
/// ASCII surface meshes of quadrangles and/or triangles. Both fill a `MembraneMeshInput`; turn
/// it into a mesh with `buildMembraneMesh`.
#include "core/HexMesh.hpp"
#include "structure/MembraneMesh.hpp"

#include <string>
#include <vector>

namespace mfsi {

/// \brief A membrane cut out of a fluid mesh baffle, and how it maps back onto the fluid mesh.
struct BaffleMembraneInput {
  MembraneMeshInput mesh;        ///< quads in master-face node order (normal = baffle normal)
  std::vector<lid_t> fluidNode;  ///< membrane node i -> fluid mesh node (size mesh.points.size())
  std::vector<lid_t> masterFace; ///< membrane element e -> face of the "<name>_master" patch (mesh face id)
  std::vector<lid_t> slaveFace;  ///< membrane element e -> the paired face of "<name>_slave"
};

/// \brief Membrane surface from the baffle `baffleName` of `mesh` (the name without the
/// "_master"/"_slave" suffix). One quad per master face with the master face's node order, so
/// the membrane normal is the baffle normal; nodes are numbered in order of first use and sit at
/// the fluid mesh's reference positions. Node sets: "boundary" (the baffle's outer edge nodes)
/// and "centre" are added by `buildMembraneMesh`. Throws InputError listing the baffles of the
/// mesh when there is no such baffle.
BaffleMembraneInput membraneMeshFromBaffle(const HexMesh& mesh, const std::string& baffleName);

/// \brief Read a membrane surface from a Gmsh MSH 4.1 ASCII file.
///
/// - Elements: the 4-node quadrangles (type 3) and 3-node triangles (type 2) of every surface
///   entity, or, when `physicalGroup` is given, only of the surface entities in the physical
///   surface group of that name (or numeric tag). Any other 2D element type is an error naming
///   the element and its line. 0D, 1D and 3D elements never become membrane elements.
/// - Node sets: every physical group of dimension 1 (2-node lines, type 1) or 0 (points,
///   type 15) becomes a node set named after the group ("line<tag>"/"point<tag>" without a name),
///   restricted to the nodes of the surface; groups with no node on the surface are dropped.
///   Higher-order lines in a physical group are an error.
/// - Nodes: only those used by membrane elements are kept, renumbered in file order.
/// - Orientation: elements keep Gmsh's node order; `buildMembraneMesh` rejects inconsistently
///   oriented neighbours (re-orient the surfaces in Gmsh, e.g. `ReverseMesh Surface{..}`).
///
/// Throws InputError naming file and line for: another version than 4.1 or a binary file,
/// malformed or truncated content, unknown node tags, unsupported element types, and a physical
/// surface group that does not exist (listing the groups that do).
MembraneMeshInput readGmshSurface(const std::string& path, const std::string& physicalGroup = "");

}  // namespace mfsi
