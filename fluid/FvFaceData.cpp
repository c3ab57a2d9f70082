#include "fluid/FvFaceData.hpp"

namespace mfsi::fluid {

FvFaceData allocateFaceData(const HexMesh& mesh) {
  FvFaceData fd;
  fd.weight = RealView("mfsi::fluid::faceData::weight", mesh.nFaces());
  fd.deltaCoeff = RealView("mfsi::fluid::faceData::deltaCoeff", mesh.nFaces());
  fd.nonOrth = Real3View("mfsi::fluid::faceData::nonOrth", mesh.nFaces());
  fd.normalDist = RealView("mfsi::fluid::faceData::normalDist", mesh.nFaces());
  return fd;
}

void computeFaceData(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo, const FvFaceData& fd) {
  ConstIndexView own = mesh.faceOwner();
  ConstIndexView nei = mesh.faceNeighbour();
  ConstReal3View cc = geo.cellCentroid;
  ConstReal3View sf = geo.faceArea;
  ConstReal3View fc = geo.faceCentroid;
  auto w = fd.weight;
  auto dc = fd.deltaCoeff;
  auto k = fd.nonOrth;
  auto nd = fd.normalDist;
  Kokkos::parallel_for(
      "mfsi::fluid::faceData::compute", RangePolicy(exec, 0, mesh.nFaces()), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f), n = nei(f);
        real d[3], S[3];
        for (int i = 0; i < 3; ++i) {
          S[i] = sf(f, i);
          d[i] = (n >= 0 ? cc(n, i) : fc(f, i)) - cc(o, i);
        }
        const real s2 = S[0] * S[0] + S[1] * S[1] + S[2] * S[2];
        const real dmag = kmath::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        real sd = S[0] * d[0] + S[1] * d[1] + S[2] * d[2];
        // Limit the non-orthogonality seen by the implicit part (cos >= 0.05), as OpenFOAM does, so
        // badly distorted faces stay bounded; the explicit correction takes the rest.
        const real sdMin = 0.05 * kmath::sqrt(s2) * dmag;
        sd = sd > sdMin ? sd : sdMin;
        dc(f) = s2 / sd;
        nd(f) = sd / kmath::sqrt(s2);
        if (n >= 0) {
          real sOwn = 0, sNei = 0;
          for (int i = 0; i < 3; ++i) {
            sOwn += S[i] * (fc(f, i) - cc(o, i));
            sNei += S[i] * (cc(n, i) - fc(f, i));
          }
          const real den = sOwn + sNei;
          w(f) = den > 0 ? sNei / den : 0.5;
          for (int i = 0; i < 3; ++i) k(f, i) = S[i] - dc(f) * d[i];
        } else {
          w(f) = 1.0;
          for (int i = 0; i < 3; ++i) k(f, i) = 0.0;
        }
      });
}

}  // namespace mfsi::fluid
