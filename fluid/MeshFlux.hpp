#pragma once
/// \file
/// \brief Face swept volumes of a moving mesh, the geometric input of the ALE scheme.
///
/// Why swept volumes: the volume a face sweeps when its nodes move linearly from old to new
/// positions is the trilinear hex spanned by the old and the new quad; summed over a cell's faces
/// (signed out of the cell) it equals the change of the cell's exact trilinear volume to round-off.
/// Mesh fluxes built from them satisfy the discrete space-conservation law exactly, so a uniform
/// flow stays uniform on any moving mesh.
#include "core/HexMesh.hpp"

namespace mfsi::fluid {

/// \brief swept(f) = volume swept by face f from `oldPoints` to `newPoints`, positive when the face
/// moves along its area vector (out of its owner). Exact for linear node paths.
void sweptVolumes(const ExecSpace& exec, const HexMesh& mesh, const ConstReal3View& oldPoints,
                  const ConstReal3View& newPoints, const RealView& swept);

/// \brief Mean velocity of the nodes of each boundary face, (new - old) / dt, into `w`
/// (size nBoundaryFaces, index f - nInternalFaces).
void boundaryFaceMeshVelocity(const ExecSpace& exec, const HexMesh& mesh, const ConstReal3View& oldPoints,
                              const ConstReal3View& newPoints, real dt, const Real3View& w);

}  // namespace mfsi::fluid
