#pragma once
/// \file
/// \brief The fluid regions of a mesh and which of them are closed chambers: a region is a set of
/// cells connected through internal faces (the two sides of a baffle are boundary faces, so a
/// membrane baffle across the domain separates two regions), and a region is closed when none of
/// its boundary faces prescribes the pressure. In a closed region of incompressible fluid the
/// inflow dictates how the walls' volume changes: a membrane that closes it must carry a volume
/// constraint (MembraneVolumeConstraint), or the partitioned coupling has no consistent fluid
/// answer (Kuettler, Foerster & Wall 2006, the incompressibility dilemma).
#include "core/HexMesh.hpp"

#include <string>
#include <vector>

namespace mfsi::coupling {

struct ChamberRegions {
  std::vector<int> cellRegion;  ///< per cell of the mesh
  int count = 0;
  std::vector<char> closed;     ///< per region: no face of a pressure patch
};

/// \brief Regions of `mesh` (the whole mesh) and, with `pressurePatches` the names of the patches
/// whose faces prescribe the pressure, which are closed.
ChamberRegions findChamberRegions(const HexMesh& mesh, const std::vector<std::string>& pressurePatches);

}  // namespace mfsi::coupling
