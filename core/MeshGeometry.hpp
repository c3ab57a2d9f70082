#pragma once
/// \file
/// \brief Geometry kernels of a hex mesh: cell volumes and centroids, face area vectors and
/// centroids, and mesh quality. Rerun after every mesh motion.
#include "core/HexMesh.hpp"

namespace mfsi {

/// \brief Geometric quantities of a mesh, as device Views (labels `mfsi::core::geometry::*`).
struct MeshGeometry {
  RealView cellVolume;     ///< exact trilinear volume
  Real3View cellCentroid;  ///< volume centroid
  Real3View faceArea;      ///< area vector, pointing out of the owner (exact for bilinear faces)
  RealView faceAreaMag;    ///< |faceArea|
  Real3View faceCentroid;  ///< area centroid
};

/// Allocate geometry Views sized for `mesh`.
MeshGeometry allocateGeometry(const HexMesh& mesh);

/// Compute all geometry of `mesh` at its current points into `geo` (no fence at the end).
void computeGeometry(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo);

/// \brief Mesh quality summary (reductions over cells and internal faces). On a rank's part of a
/// mesh the sums count what the rank owns: its owned cells, and each internal face once over all
/// ranks (a face between an owned and a ghost cell on the rank of the lower global cell id).
struct MeshQuality {
  double minScaledJacobian = 0;  ///< over all cell corners; 1 = cube, <= 0 inverted
  double maxNonOrthogonality = 0;  ///< degrees, angle between owner->neighbour and face normal
  double meanNonOrthogonality = 0;  ///< degrees, over internal faces
  long long countedFaces = 0;  ///< the internal faces the mean is over
  double maxSkewness = 0;  ///< OpenFOAM-style: |face centroid - intersection| / |owner->neighbour|
  double totalVolume = 0;
  double minVolume = 0;
  double maxVolume = 0;
};

/// Compute the quality of `mesh` given its computed geometry (fences, returns host values).
MeshQuality computeQuality(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo);

/// The minimum scaled Jacobian over all cell corners at the current points (no geometry needed:
/// one reduction; fences). The same value as `computeQuality(...).minScaledJacobian`.
double minScaledJacobian(const ExecSpace& exec, const HexMesh& mesh);

/// The minimum scaled Jacobian of each cell over its corners at the current points, into `out`
/// (nCells; for output and for finding the worst cells; no fence).
void cellScaledJacobians(const ExecSpace& exec, const HexMesh& mesh, const RealView& out);

}  // namespace mfsi
