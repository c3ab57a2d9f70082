#pragma once
/// \file
/// \brief Reader for Gmsh meshes (MSH 4.1 ASCII) made of 8-node hexahedra.
#include "core/HexMesh.hpp"

#include <string>

namespace mfsi {

/// \brief Read a Gmsh MSH 4.1 ASCII file into a `HexMeshInput` (turn it into a mesh with
/// `buildHexMesh`).
///
/// - Cells: the 8-node hexahedra (element type 5); Gmsh's hex node order is ours. Any other 3D
///   element (tetrahedra, prisms, pyramids, second-order hexahedra, ...) is an error "non-hex
///   cell" naming the element and its line.
/// - Patches: the 4-node quadrangles (type 3) on surface entities that belong to a physical
///   group, one patch per physical name ("patch<tag>" for a group without a name), ordered by
///   physical tag, kind `PatchKind::Patch`. Surface elements of entities without a physical
///   group, and all 0D/1D elements, are ignored; boundary faces no patch claims end up in
///   `HexMeshInput::defaultPatch`.
/// - Baffles: a physical group whose quadrangles are all internal faces (each shared by two
///   hexahedra) is a baffle of that name instead (a membrane inside the flow); its quadrangles'
///   node order sets the baffle normal, which points out of the master side. A group with both
///   boundary and internal faces is an error.
/// - Nodes: tags may be sparse and in any order; only nodes used by a hexahedron are kept,
///   renumbered 0..n-1 in file order.
///
/// Throws InputError naming the file and line for: another version than 4.1 or a binary file,
/// malformed or truncated content, unknown node tags, non-hex and inverted cells.
HexMeshInput readGmsh(const std::string& path);

}  // namespace mfsi
