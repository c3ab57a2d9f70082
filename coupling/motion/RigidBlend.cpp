#include "coupling/motion/RigidBlend.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"
#include "core/PointTree.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace mfsi::coupling {

double RigidBlend::weight(double distance, double inner, double outer) {
  if (distance <= inner) return 1;
  if (distance >= outer) return 0;
  return 0.5 * (1 + std::cos(M_PI * (distance - inner) / (outer - inner)));
}

std::vector<double> RigidBlend::nearestDistance(const HexMesh& mesh, const std::vector<std::array<real, 3>>& sources) {
  const PointTree tree(sources);
  auto X = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  std::vector<double> dist(static_cast<std::size_t>(mesh.nNodes()));
  for (lid_t v = 0; v < mesh.nNodes(); ++v)
    dist[static_cast<std::size_t>(v)] = std::sqrt(tree.nearestSquaredDistance({X(v, 0), X(v, 1), X(v, 2)}));
  return dist;
}

RigidBlend::RigidBlend(const std::vector<Body>& bodies, const HexMesh& mesh)
    : nBodies_(static_cast<int>(bodies.size())) {
  if (nBodies_ == 0) return;
  const lid_t n = mesh.nNodes();
  std::vector<std::vector<double>> distances;
  for (const Body& b : bodies) {
    MFSI_CHECK(b.outerDistance > b.innerDistance && b.innerDistance >= 0,
               "rigid blend: the distances must satisfy 0 <= innerDistance < outerDistance");
    distances.push_back(nearestDistance(mesh, b.points));
  }
  hostWeights_.assign(static_cast<std::size_t>(n) * nBodies_, 0);
  for (lid_t v = 0; v < n; ++v)
    for (int b = 0; b < nBodies_; ++b)
      hostWeights_[static_cast<std::size_t>(v) * nBodies_ + b] = static_cast<real>(
          weight(distances[b][static_cast<std::size_t>(v)], bodies[b].innerDistance, bodies[b].outerDistance));
  weights_ = Kokkos::View<real**, MemSpace>("mfsi::coupling::rigidBlend::weights", n, nBodies_);
  auto hw = Kokkos::create_mirror_view(weights_);
  for (lid_t v = 0; v < n; ++v)
    for (int b = 0; b < nBodies_; ++b) hw(v, b) = hostWeights_[static_cast<std::size_t>(v) * nBodies_ + b];
  Kokkos::deep_copy(weights_, hw);
  reference_ = mesh.referencePoints();
  screws_ = Kokkos::View<real* [10], MemSpace>("mfsi::coupling::rigidBlend::screws", nBodies_);
}

void RigidBlend::displacement(const ExecSpace& exec, const std::vector<RigidPlacement>& transforms,
                              const Real3View& base) const {
  MFSI_ASSERT(static_cast<int>(transforms.size()) == nBodies_, "rigid blend: one transform per body");
  auto hs = Kokkos::create_mirror_view(screws_);
  for (int b = 0; b < nBodies_; ++b) {
    const RigidPlacement& T = transforms[b];
    Eigen::Matrix3d R;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R(i, j) = T.rotation[i][j];
    const Eigen::AngleAxisd aa(R);  // angle in [0, pi]
    for (int k = 0; k < 3; ++k) {
      hs(b, k) = T.origin[k];
      hs(b, 3 + k) = T.placed[k] - T.origin[k];
      hs(b, 6 + k) = aa.axis()[k];
    }
    hs(b, 9) = aa.angle();
  }
  Kokkos::deep_copy(exec, screws_, hs);
  const auto w = weights_;
  const auto screw = screws_;
  const ConstReal3View X = reference_;
  const Real3View out = base;
  const int nb = nBodies_;
  Kokkos::parallel_for(
      "mfsi::coupling::rigidBlend::displacement", RangePolicy(exec, 0, static_cast<lid_t>(w.extent(0))),
      KOKKOS_LAMBDA(lid_t v) {
        real sum = 0;
        for (int b = 0; b < nb; ++b) sum += w(v, b);
        const real scale = sum > 1 ? real(1) / sum : real(1);
        real d[3] = {0, 0, 0};
        for (int b = 0; b < nb; ++b) {
          const real wb = scale * w(v, b);
          if (wb == 0) continue;
          // Rodrigues: the rotation by wb * angle about the axis, applied to r = X - origin.
          const real r[3] = {X(v, 0) - screw(b, 0), X(v, 1) - screw(b, 1), X(v, 2) - screw(b, 2)};
          const real a[3] = {screw(b, 6), screw(b, 7), screw(b, 8)};
          const real phi = wb * screw(b, 9), c = kmath::cos(phi), s = kmath::sin(phi);
          const real ar = a[0] * r[0] + a[1] * r[1] + a[2] * r[2];
          real axr[3];
          geom::cross(a, r, axr);
          for (int k = 0; k < 3; ++k)
            d[k] += wb * screw(b, 3 + k) + (c - 1) * r[k] + s * axr[k] + (1 - c) * ar * a[k];
        }
        for (int k = 0; k < 3; ++k) out(v, k) = d[k];
      });
}

}  // namespace mfsi::coupling
