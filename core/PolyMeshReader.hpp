#pragma once
/// \file
/// \brief Reader for OpenFOAM polyMesh directories (ASCII) made of hexahedra.
#include "core/HexMesh.hpp"

#include <string>

namespace mfsi {

/// \brief Read an OpenFOAM polyMesh directory (`points`, `faces`, `owner`, `neighbour`,
/// `boundary`, ASCII format) into a `HexMeshInput` (turn it into a mesh with `buildHexMesh`).
///
/// OpenFOAM stores cells only implicitly, as the faces they own or neighbour. Each cell must
/// have exactly six 4-node faces that close up as a hexahedron; its 8 nodes are rebuilt in our
/// hex order with positive volume. Cells keep OpenFOAM's numbering; nodes keep theirs.
/// Patches come from `boundary` in its order, with kinds wall -> Wall, symmetry/symmetryPlane
/// -> Symmetry, empty -> Empty, anything else -> Patch.
///
/// Throws InputError naming the file (and line where one applies) for: missing or compressed
/// files, binary format, malformed content, non-hex cells ("non-hex cell <id>"), patch ranges
/// outside the boundary faces, and decomposed (processor) meshes. Sizes and labels are checked
/// before anything is allocated from them: a list size the rest of its file cannot hold, and an
/// owner/neighbour label outside [0, nCells) (nCells from the header's note, at most half the
/// faces) are refused naming the line and entry.
HexMeshInput readPolyMesh(const std::string& dir);

}  // namespace mfsi
