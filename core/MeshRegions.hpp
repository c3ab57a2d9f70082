#pragma once
/// \file
/// \brief The regions of a mesh: a region is a set of cells connected through internal faces (the
/// two sides of a baffle are boundary faces, so a membrane baffle across the domain separates two
/// regions). A region is closed to a set of patches when none of its boundary faces lies on one.
/// Uses: the fluid's closed chambers (no pressure patch reaches them: in a closed region of
/// incompressible fluid the inflow dictates how the walls' volume changes, so a membrane that
/// closes it must carry a volume constraint, MembraneVolumeConstraint, or the partitioned coupling
/// has no consistent fluid answer: Kuettler, Foerster & Wall 2006, the incompressibility dilemma),
/// and the fluid's material regions (FluidOptions::regions: the cells a named patch reaches).
#include "core/HexMesh.hpp"
#include "core/parallel/Halo.hpp"

#include <string>
#include <vector>

namespace mfsi {

struct MeshRegions {
  std::vector<int> cellRegion;  ///< per cell of the mesh (of the rank's part: owned and ghost)
  int count = 0;
  std::vector<char> closed;     ///< per region: no face of one of the patches asked about
  std::vector<gid_t> firstCell;  ///< per region: its cell of least global id (regions are in this order)
};

/// \brief Regions of `mesh` and which of them no face of the patches named `patches` reaches (for
/// the fluid's chambers: the patches that prescribe the pressure). On a rank's part of a decomposed
/// mesh (`domain` distributed) the regions are the whole mesh's, numbered alike on every rank and
/// on one rank (collective; no rank needs the whole mesh).
MeshRegions findMeshRegions(const HexMesh& mesh, const std::vector<std::string>& patches,
                            const RankDomain& domain = RankDomain{});

}  // namespace mfsi
