#pragma once
/// \file
/// \brief A membrane cut from a decomposed fluid mesh: the rank whose cells hold the whole baffle
/// or patch (a decomposition keeps them on one rank) cuts it from its part, and every other rank
/// receives the same surface, so no rank needs the whole fluid mesh. The surface is the one the
/// whole mesh gives, node for node and element for element: its nodes and faces are named by
/// global ids, and a part lists a patch's faces in the whole mesh's order.
#include "core/HexMesh.hpp"
#include "structure/membrane/MembraneMeshImport.hpp"

#include <mpi.h>

#include <string>

namespace mfsi {

/// \brief Which of a fluid mesh's surfaces a membrane is cut from.
struct FluidSurfaceName {
  std::string name;
  bool baffle = true;  ///< a baffle (both sides), else a one-sided boundary patch
};

/// \brief membraneMeshFromBaffle / membraneMeshFromPatch of the whole mesh, from the ranks' parts
/// (`part`: this rank's; collective over `comm`). `masterFace` and `slaveFace` are filled on the
/// rank that cut it only. Throws the same InputError on every rank when the surface does not exist
/// or its faces are owned by several ranks.
FluidSurfaceMembraneInput cutMembraneOnRanks(const HexMesh& part, const FluidSurfaceName& surface, MPI_Comm comm);

}  // namespace mfsi
