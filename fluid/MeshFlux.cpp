#include "fluid/MeshFlux.hpp"

#include "core/HexGeometry.hpp"

namespace mfsi::fluid {

void sweptVolumes(const ExecSpace& exec, const HexMesh& mesh, const ConstReal3View& oldPoints,
                  const ConstReal3View& newPoints, const RealView& swept) {
  ConstQuad4View fn = mesh.faceNodes();
  Kokkos::parallel_for(
      "mfsi::fluid::meshFlux::sweptVolume", RangePolicy(exec, 0, mesh.nFaces()), KOKKOS_LAMBDA(lid_t f) {
        // Hex with the old quad at the bottom and the new quad on top. The face's node order gives
        // a normal pointing from bottom to top for a positively oriented hex, so the volume is
        // positive when the face moves along its area vector.
        double x[8][3];
        for (int a = 0; a < 4; ++a)
          for (int k = 0; k < 3; ++k) {
            x[a][k] = oldPoints(fn(f, a), k);
            x[a + 4][k] = newPoints(fn(f, a), k);
          }
        swept(f) = geom::hexVolume(x);
      });
}

void boundaryFaceMeshVelocity(const ExecSpace& exec, const HexMesh& mesh, const ConstReal3View& oldPoints,
                              const ConstReal3View& newPoints, real dt, const Real3View& w) {
  ConstQuad4View fn = mesh.faceNodes();
  const lid_t nIn = mesh.nInternalFaces();
  const real rdt = dt > 0 ? 1.0 / dt : 0.0;
  Kokkos::parallel_for(
      "mfsi::fluid::meshFlux::faceVelocity", RangePolicy(exec, 0, mesh.nBoundaryFaces()), KOKKOS_LAMBDA(lid_t b) {
        const lid_t f = b + nIn;
        for (int k = 0; k < 3; ++k) {
          real s = 0;
          for (int a = 0; a < 4; ++a) s += newPoints(fn(f, a), k) - oldPoints(fn(f, a), k);
          w(b, k) = 0.25 * s * rdt;
        }
      });
}

}  // namespace mfsi::fluid
