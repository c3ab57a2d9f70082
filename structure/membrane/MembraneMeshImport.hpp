#pragma once
/// \file
/// \brief Membrane surfaces that do not come from a generator: the master side of a baffle of
/// the fluid mesh (with the membrane node -> fluid node map the coupling needs), and Gmsh 4.1
/// ASCII surface meshes of quadrangles and/or triangles. Both fill a `MembraneMeshInput`; turn
/// it into a mesh with `buildMembraneMesh`.
#include "core/HexMesh.hpp"
#include "structure/membrane/MembraneMesh.hpp"

#include <string>
#include <vector>

namespace mfsi {

/// \brief A membrane cut out of the fluid mesh (a baffle or a one-sided boundary patch), and how
/// it maps back onto the fluid mesh.
struct FluidSurfaceMembraneInput {
  MembraneMeshInput mesh;         ///< one quad per face, in the face's node order (normal = face normal)
  std::vector<gid_t> fluidNode;   ///< membrane node i -> fluid mesh node, by global id (size mesh.points.size())
  /// Membrane element e -> its face in the mesh it was cut from: of "<name>_master", or of the
  /// patch. Empty on a rank that received the surface from the rank that cut it (cutMembraneOnRanks).
  std::vector<lid_t> masterFace;
  std::vector<lid_t> slaveFace;   ///< baffle: element e -> the paired face of "<name>_slave"; patch: empty
  /// The same faces named by their nodes' global ids, in the face's node order: valid on every rank.
  std::vector<std::array<gid_t, 4>> masterFaceNodes, slaveFaceNodes;
  lid_t nElements() const { return static_cast<lid_t>(masterFaceNodes.size()); }
};

/// \brief Membrane surface from the baffle `baffleName` of `mesh` (the name without the
/// "_master"/"_slave" suffix). One quad per master face with the master face's node order, so
/// the membrane normal is the baffle normal; nodes are numbered in order of first use and sit at
/// the fluid mesh's reference positions. Node sets: "xmin" ... "zmax" (the nodes on each side of
/// the surface's bounding box, where it is not flat in that axis); "boundary" (the outer edge) and
/// "centre" are added by `buildMembraneMesh`. Throws InputError listing the baffles of the mesh
/// when there is no such baffle.
FluidSurfaceMembraneInput membraneMeshFromBaffle(const HexMesh& mesh, const std::string& baffleName);

/// \brief Membrane surface on the one-sided boundary patch `patchName` (a wall the membrane
/// replaces: a cavity bottom, a tube wall). As for a baffle; the membrane normal is the patch's
/// outward normal (out of the fluid), so a positive load pressure is the fluid pushing the wall
/// out. Throws InputError listing the patches for an unknown name or a baffle side.
FluidSurfaceMembraneInput membraneMeshFromPatch(const HexMesh& mesh, const std::string& patchName);

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
