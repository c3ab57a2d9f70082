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
#include "core/parallel/Halo.hpp"

#include <string>
#include <vector>

namespace mfsi::coupling {

struct ChamberRegions {
  std::vector<int> cellRegion;  ///< per cell of the mesh (of the rank's part: owned and ghost)
  int count = 0;
  std::vector<char> closed;     ///< per region: no face of a pressure patch
  std::vector<gid_t> firstCell;  ///< per region: its cell of least global id (regions are in this order)
};

/// \brief Regions of `mesh` and, with `pressurePatches` the names of the patches whose faces
/// prescribe the pressure, which are closed. On a rank's part of a decomposed mesh (`domain`
/// distributed) the regions are the whole mesh's, numbered alike on every rank and on one rank
/// (collective; no rank needs the whole mesh).
ChamberRegions findChamberRegions(const HexMesh& mesh, const std::vector<std::string>& pressurePatches,
                                  const RankDomain& domain = RankDomain{});

}  // namespace mfsi::coupling
