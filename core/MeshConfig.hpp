#pragma once
/// \file
/// \brief Config layer of the `mesh` section: its schema, and the mesh it describes (generated
/// blocks, a Gmsh .msh file or an OpenFOAM polyMesh directory).
#include "core/HexMesh.hpp"
#include "core/SceneConfig.hpp"

namespace mfsi {

/// Schema of the `mesh` section.
Schema meshSchema();

/// Build the mesh described by `mesh` (a view of the `mesh` section). Relative file paths are
/// taken relative to the scene file's folder. Throws InputError naming the scene key on errors;
/// for generated blocks also, before allocating anything, when the cells, nodes or faces overflow
/// lid_t or the estimated memory (about 5 kB per cell, solver included) exceeds the machine's
/// physical memory, and when touching blocks differ in grid on the shared face (naming both).
HexMesh buildMesh(const SceneConfig& mesh);

}  // namespace mfsi
