#include "core/MeshGeometry.hpp"

#include "core/HexGeometry.hpp"

namespace mfsi {

MeshGeometry allocateGeometry(const HexMesh& mesh) {
  MeshGeometry g;
  g.cellVolume = RealView("mfsi::core::geometry::cellVolume", mesh.nCells());
  g.cellCentroid = Real3View("mfsi::core::geometry::cellCentroid", mesh.nCells());
  g.faceArea = Real3View("mfsi::core::geometry::faceArea", mesh.nFaces());
  g.faceAreaMag = RealView("mfsi::core::geometry::faceAreaMag", mesh.nFaces());
  g.faceCentroid = Real3View("mfsi::core::geometry::faceCentroid", mesh.nFaces());
  return g;
}

void computeGeometry(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo) {
  ScopedRegion region("mfsi::core::geometry");
  ConstReal3View pts = mesh.points();
  ConstHex8View cn = mesh.cellNodes();
  ConstQuad4View fn = mesh.faceNodes();
  auto vol = geo.cellVolume;
  auto cc = geo.cellCentroid;
  auto sf = geo.faceArea;
  auto sm = geo.faceAreaMag;
  auto fc = geo.faceCentroid;
  Kokkos::parallel_for(
      "mfsi::core::geometry::cells", RangePolicy(exec, 0, mesh.nCells()), KOKKOS_LAMBDA(lid_t c) {
        double x[8][3];
        for (int a = 0; a < 8; ++a)
          for (int k = 0; k < 3; ++k) x[a][k] = pts(cn(c, a), k);
        double v, ctr[3];
        geom::hexVolumeCentroid(x, v, ctr);
        vol(c) = v;
        for (int k = 0; k < 3; ++k) cc(c, k) = ctr[k];
      });
  Kokkos::parallel_for(
      "mfsi::core::geometry::faces", RangePolicy(exec, 0, mesh.nFaces()), KOKKOS_LAMBDA(lid_t f) {
        double x[4][3];
        for (int a = 0; a < 4; ++a)
          for (int k = 0; k < 3; ++k) x[a][k] = pts(fn(f, a), k);
        double s[3], ctr[3], area;
        geom::quadAreaVector(x, s);
        geom::quadCentroid(x, ctr, area);
        for (int k = 0; k < 3; ++k) {
          sf(f, k) = s[k];
          fc(f, k) = ctr[k];
        }
        sm(f) = geom::norm(s);
      });
}

namespace {
/// The minimum scaled Jacobian over the corners of cell c at the current points.
KOKKOS_INLINE_FUNCTION double cellMinScaledJacobian(const ConstReal3View& pts, const ConstHex8View& cn, lid_t c) {
  double x[8][3];
  for (int a = 0; a < 8; ++a)
    for (int k = 0; k < 3; ++k) x[a][k] = pts(cn(c, a), k);
  return geom::hexMinScaledJacobian(x);
}
}  // namespace

double minScaledJacobian(const ExecSpace& exec, const HexMesh& mesh) {
  ConstReal3View pts = mesh.points();
  ConstHex8View cn = mesh.cellNodes();
  double jmin = 0;
  Kokkos::parallel_reduce(
      "mfsi::core::quality::minScaledJacobian", RangePolicy(exec, 0, mesh.nCells()),
      KOKKOS_LAMBDA(lid_t c, double& m) {
        const double j = cellMinScaledJacobian(pts, cn, c);
        m = j < m ? j : m;
      },
      Kokkos::Min<double>(jmin));
  exec.fence();
  return jmin;
}

void cellScaledJacobians(const ExecSpace& exec, const HexMesh& mesh, const RealView& out) {
  ConstReal3View pts = mesh.points();
  ConstHex8View cn = mesh.cellNodes();
  Kokkos::parallel_for(
      "mfsi::core::quality::cellScaledJacobians", RangePolicy(exec, 0, mesh.nCells()),
      KOKKOS_LAMBDA(lid_t c) { out(c) = cellMinScaledJacobian(pts, cn, c); });
}

MeshQuality computeQuality(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo) {
  ScopedRegion region("mfsi::core::quality");
  ConstRealView vol = geo.cellVolume;
  MeshQuality q;
  q.minScaledJacobian = minScaledJacobian(exec, mesh);
  Kokkos::parallel_reduce(
      "mfsi::core::quality::cells", RangePolicy(exec, 0, mesh.nOwnedCells()),
      KOKKOS_LAMBDA(lid_t c, double& vsum, double& vmin, double& vmax) {
        vsum += vol(c);
        vmin = vol(c) < vmin ? vol(c) : vmin;
        vmax = vol(c) > vmax ? vol(c) : vmax;
      },
      q.totalVolume, Kokkos::Min<double>(q.minVolume), Kokkos::Max<double>(q.maxVolume));

  ConstIndexView own = mesh.faceOwner();
  ConstIndexView nei = mesh.faceNeighbour();
  ConstReal3View cc = geo.cellCentroid;
  ConstReal3View sf = geo.faceArea;
  ConstReal3View fc = geo.faceCentroid;
  const auto gid = mesh.cellGlobalIds();
  const lid_t nOwned = mesh.nOwnedCells();
  double sumAngle = 0.0;
  long long counted = 0;
  const lid_t nIn = mesh.nInternalFaces();
  Kokkos::parallel_reduce(
      "mfsi::core::quality::faces", RangePolicy(exec, 0, nIn),
      KOKKOS_LAMBDA(lid_t f, double& amax, double& asum, double& smax, long long& count) {
        const lid_t o = own(f), n = nei(f);
        // Each face once over the ranks: by the rank that owns its cell of the lower global id.
        const lid_t first = gid(o) < gid(n) ? o : n;
        if (first >= nOwned) return;
        ++count;
        double d[3], s[3];
        for (int k = 0; k < 3; ++k) {
          d[k] = cc(n, k) - cc(o, k);
          s[k] = sf(f, k);
        }
        const double dn = geom::norm(d), snorm = geom::norm(s);
        double cosv = geom::dot(d, s) / (dn * snorm);
        cosv = cosv > 1.0 ? 1.0 : (cosv < -1.0 ? -1.0 : cosv);
        const double angle = kmath::acos(cosv) * 57.29577951308232;
        amax = angle > amax ? angle : amax;
        asum += angle;
        // Skewness: where the owner->neighbour line meets the face plane, vs the face centroid.
        double po[3];
        for (int k = 0; k < 3; ++k) po[k] = fc(f, k) - cc(o, k);
        const double t = geom::dot(po, s) / geom::dot(d, s);
        double e[3];
        for (int k = 0; k < 3; ++k) e[k] = cc(o, k) + t * d[k] - fc(f, k);
        const double sk = geom::norm(e) / dn;
        smax = sk > smax ? sk : smax;
      },
      Kokkos::Max<double>(q.maxNonOrthogonality), sumAngle, Kokkos::Max<double>(q.maxSkewness), counted);
  q.countedFaces = counted;
  q.meanNonOrthogonality = counted > 0 ? sumAngle / static_cast<double>(counted) : 0.0;
  if (counted == 0) {
    q.maxNonOrthogonality = 0.0;
    q.maxSkewness = 0.0;
  }
  return q;
}

}  // namespace mfsi
