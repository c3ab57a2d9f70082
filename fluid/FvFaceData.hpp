#pragma once
/// \file
/// \brief Per-face discretisation data derived from the geometry: linear-interpolation weights,
/// over-relaxed non-orthogonal diffusion coefficients and correction vectors. Recompute after
/// every mesh motion (with `computeGeometry`).
#include "core/MeshGeometry.hpp"

namespace mfsi::fluid {

/// \brief Face data of the cell-centred scheme (labels `mfsi::fluid::faceData::*`).
///
/// For an internal face with owner P, neighbour N, area vector S and d = x_N - x_P:
/// `weight` is the owner's share in a linear interpolation, w = S.(x_N - x_f) / S.(x_N - x_P);
/// `deltaCoeff` = |S|^2 / (S.d) so that |S| dphi/dn ~ deltaCoeff (phi_N - phi_P) (over-relaxed
/// splitting, the implicit part is as large as the face allows); `nonOrth` = S - deltaCoeff d is the
/// vector that multiplies the interpolated gradient in the explicit correction. Boundary faces use
/// d = x_f - x_P, weight 1 and no correction.
struct FvFaceData {
  RealView weight;      ///< size nFaces
  RealView deltaCoeff;  ///< size nFaces
  Real3View nonOrth;    ///< size nFaces
  RealView normalDist;  ///< S.d / |S|: normal distance owner -> neighbour (or -> boundary face)
};

/// Allocate face data for `mesh`.
FvFaceData allocateFaceData(const HexMesh& mesh);

/// Compute face data from computed geometry (no fence).
void computeFaceData(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo, const FvFaceData& fd);

}  // namespace mfsi::fluid
