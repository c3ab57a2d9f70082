#include "coupling/motion/ParentFrames.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"
#include "kernels/Blas.hpp"

#include <algorithm>
#include <limits>

namespace mfsi::coupling {

ParentFrames::ParentFrames(const std::vector<std::array<real, 3>>& nodes,
                           const std::vector<std::array<real, 3>>& candidates, const std::vector<int>& candidateBody,
                           int nBodies)
    : nBodies_(nBodies) {
  MFSI_CHECK(!candidates.empty() && candidates.size() == candidateBody.size(),
             "parent frames: no parent patch nodes to follow");
  // Nearest candidate of each body by brute force, once at set-up (membrane nodes x patch nodes).
  const std::size_t nb = static_cast<std::size_t>(nBodies);
  hostWeights_.assign(nodes.size() * nb, 0.0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    std::vector<double> d2(nb, std::numeric_limits<double>::max());
    for (std::size_t j = 0; j < candidates.size(); ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += (nodes[i][k] - candidates[j][k]) * (nodes[i][k] - candidates[j][k]);
      d2[candidateBody[j]] = std::min(d2[candidateBody[j]], s);
    }
    double* w = &hostWeights_[i * nb];
    const auto on = std::min_element(d2.begin(), d2.end());
    if (*on == 0.0) {  // on a parent's patch: that body alone
      w[on - d2.begin()] = 1;
      continue;
    }
    double sum = 0;
    for (std::size_t b = 0; b < nb; ++b) {
      w[b] = d2[b] < std::numeric_limits<double>::max() ? 1.0 / d2[b] : 0.0;
      sum += w[b];
    }
    for (std::size_t b = 0; b < nb; ++b) w[b] /= sum;
  }
  weights_ = Kokkos::View<double**, MemSpace>("mfsi::coupling::parentFrames::weights", nodes.size(), nb);
  auto h = Kokkos::create_mirror_view(weights_);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (std::size_t b = 0; b < nb; ++b) h(i, b) = hostWeights_[i * nb + b];
  Kokkos::deep_copy(weights_, h);
  frames_ = Kokkos::View<double* [15], MemSpace>("mfsi::coupling::parentFrames::frames", nBodies);
  std::vector<RigidPlacement> identity(static_cast<std::size_t>(nBodies));
  setTransforms(identity);
}

void ParentFrames::setTransforms(const std::vector<RigidPlacement>& transforms) {
  MFSI_CHECK(static_cast<int>(transforms.size()) == nBodies_, "parent frames: one transform per body expected");
  auto h = Kokkos::create_mirror_view(frames_);
  for (int b = 0; b < nBodies_; ++b) {
    const std::array<real, 15> f = transforms[b].flat();
    for (int k = 0; k < 15; ++k) h(b, k) = f[k];
  }
  Kokkos::deep_copy(frames_, h);
}

namespace {

/// x = sum_b w_ib (c_b + Q_b (X_i + u_i - c0_b)): where node i sits.
template <class Weights, class Frames>
KOKKOS_INLINE_FUNCTION void placedNode(const Weights& W, const Frames& F, int nb, lid_t i, const ConstReal3View& X,
                                       const ConstRealView& u, real x[3]) {
  x[0] = x[1] = x[2] = 0;
  for (int b = 0; b < nb; ++b) {
    const real w = W(i, b);
    if (w == 0) continue;
    real r[3];
    for (int k = 0; k < 3; ++k) r[k] = X(i, k) + u(3 * i + k) - F(b, k);
    for (int k = 0; k < 3; ++k)
      x[k] += w * (F(b, 3 + k) + F(b, 6 + 3 * k) * r[0] + F(b, 7 + 3 * k) * r[1] + F(b, 8 + 3 * k) * r[2]);
  }
}

/// acc += (F, r x F).
KOKKOS_INLINE_FUNCTION void addForceAndMoment(blas::Sums<6>& acc, const real F[3], const real r[3]) {
  acc[0] += F[0];
  acc[1] += F[1];
  acc[2] += F[2];
  acc[3] += r[1] * F[2] - r[2] * F[1];
  acc[4] += r[2] * F[0] - r[0] * F[2];
  acc[5] += r[0] * F[1] - r[1] * F[0];
}

}  // namespace

void ParentFrames::displacement(const ExecSpace& exec, const ConstReal3View& reference, const ConstRealView& relative,
                                const ConstIndexView& fluidNode, const Real3View& meshDisplacement) const {
  const auto W = weights_;
  const auto F = frames_;
  const int nb = nBodies_;
  Kokkos::parallel_for(
      "mfsi::coupling::parentFrames::displacement", RangePolicy(exec, 0, static_cast<lid_t>(weights_.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        if (fluidNode(i) < 0) return;  // not on this rank's part of the mesh
        real x[3];
        placedNode(W, F, nb, i, reference, relative, x);
        for (int k = 0; k < 3; ++k) meshDisplacement(fluidNode(i), k) = x[k] - reference(i, k);
      });
}

void ParentFrames::positions(const ExecSpace& exec, const ConstReal3View& reference, const ConstRealView& relative,
                             const Real3View& x) const {
  const auto W = weights_;
  const auto F = frames_;
  const int nb = nBodies_;
  Kokkos::parallel_for(
      "mfsi::coupling::parentFrames::positions", RangePolicy(exec, 0, static_cast<lid_t>(weights_.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        real y[3];
        placedNode(W, F, nb, i, reference, relative, y);
        for (int k = 0; k < 3; ++k) x(i, k) = y[k];
      });
}

void ParentFrames::setAccelerations(const std::vector<BodyAcceleration>& accelerations) {
  MFSI_CHECK(static_cast<int>(accelerations.size()) == nBodies_, "parent frames: one acceleration per body expected");
  if (accelerations_.extent(0) != static_cast<std::size_t>(nBodies_))
    accelerations_ = Kokkos::View<double* [12], MemSpace>("mfsi::coupling::parentFrames::accelerations", nBodies_);
  auto h = Kokkos::create_mirror_view(accelerations_);
  for (int b = 0; b < nBodies_; ++b)
    for (int k = 0; k < 3; ++k) {
      h(b, k) = accelerations[b].centre[k];
      h(b, 3 + k) = accelerations[b].acceleration[k];
      h(b, 6 + k) = accelerations[b].omega[k];
      h(b, 9 + k) = accelerations[b].alpha[k];
    }
  Kokkos::deep_copy(accelerations_, h);
}

void ParentFrames::inertialForce(const ExecSpace& exec, const ConstReal3View& x, const ConstRealView& relativeVelocity,
                                 const ConstRealView& mass, const Real3View& f) const {
  frameInertia(exec, x, relativeVelocity, ConstRealView(), mass, f);
}

void ParentFrames::relativeInertia(const ExecSpace& exec, const ConstRealView& relativeVelocity,
                                   const ConstRealView& relativeAcceleration, const ConstRealView& mass,
                                   const Real3View& f) const {
  frameInertia(exec, ConstReal3View(), relativeVelocity, relativeAcceleration, mass, f);
}

void ParentFrames::frameInertia(const ExecSpace& exec, const ConstReal3View& x, const ConstRealView& relativeVelocity,
                                const ConstRealView& relativeAcceleration, const ConstRealView& mass,
                                const Real3View& f) const {
  MFSI_CHECK(accelerations_.extent(0) == static_cast<std::size_t>(nBodies_),
             "parent frames: inertial forces before setAccelerations");
  const auto W = weights_;
  const auto A = accelerations_;
  const auto F = frames_;
  const int nb = nBodies_;
  const bool carried = relativeAcceleration.extent(0) == 0;
  Kokkos::parallel_for(
      "mfsi::coupling::parentFrames::inertialForce", RangePolicy(exec, 0, static_cast<lid_t>(weights_.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        real acc[3] = {0, 0, 0};
        for (int b = 0; b < nb; ++b) {
          const real w = W(i, b);
          if (w == 0) continue;
          const real o[3] = {A(b, 6), A(b, 7), A(b, 8)};
          real v[3];  // the relative velocity in world axes: Q v, (Q v)_j = sum_k Q_jk v_k
          for (int j = 0; j < 3; ++j)
            v[j] = F(b, 6 + 3 * j) * relativeVelocity(3 * i) + F(b, 7 + 3 * j) * relativeVelocity(3 * i + 1) +
                   F(b, 8 + 3 * j) * relativeVelocity(3 * i + 2);
          real oxv[3];  // omega x v: the Coriolis term, in both
          geom::cross(o, v, oxv);
          for (int k = 0; k < 3; ++k) acc[k] += w * 2 * oxv[k];
          if (carried) {
            const real r[3] = {x(i, 0) - A(b, 0), x(i, 1) - A(b, 1), x(i, 2) - A(b, 2)};
            const real al[3] = {A(b, 9), A(b, 10), A(b, 11)};
            real oxr[3], axr[3], ooxr[3];  // omega x r, alpha x r, omega x (omega x r)
            geom::cross(o, r, oxr);
            geom::cross(al, r, axr);
            geom::cross(o, oxr, ooxr);
            for (int k = 0; k < 3; ++k) acc[k] += w * (A(b, 3 + k) + axr[k] + ooxr[k]);
          } else {
            for (int k = 0; k < 3; ++k)  // Q a
              acc[k] += w * (F(b, 6 + 3 * k) * relativeAcceleration(3 * i) +
                             F(b, 7 + 3 * k) * relativeAcceleration(3 * i + 1) +
                             F(b, 8 + 3 * k) * relativeAcceleration(3 * i + 2));
          }
        }
        for (int k = 0; k < 3; ++k) f(i, k) = -mass(i) * acc[k];
      });
}

void ParentFrames::toFrames(const ExecSpace& exec, const ConstReal3View& global, const Real3View& relative) const {
  const auto W = weights_;
  const auto F = frames_;
  const int nb = nBodies_;
  Kokkos::parallel_for(
      "mfsi::coupling::parentFrames::toFrames", RangePolicy(exec, 0, static_cast<lid_t>(weights_.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        real y[3] = {0, 0, 0};
        for (int b = 0; b < nb; ++b) {
          const real w = W(i, b);
          if (w == 0) continue;
          for (int k = 0; k < 3; ++k)  // (Q^T f)_k = sum_j Q_jk f_j
            y[k] += w * (F(b, 6 + k) * global(i, 0) + F(b, 9 + k) * global(i, 1) + F(b, 12 + k) * global(i, 2));
        }
        for (int k = 0; k < 3; ++k) relative(i, k) = y[k];
      });
}

std::array<double, 6> ParentFrames::nodeLoad(const ExecSpace& exec, int slot, const std::array<double, 3>& centre,
                                             const ConstReal3View& x, const ConstReal3View& f) const {
  const auto W = weights_;
  const int s = slot;
  const real cx = centre[0], cy = centre[1], cz = centre[2];
  return blas::reduce<6>(
      exec, SolverComm{}, "mfsi::coupling::parentFrames::nodeLoad", static_cast<lid_t>(weights_.extent(0)),
      KOKKOS_LAMBDA(lid_t i, blas::Sums<6> & acc) {
        const real w = W(i, s);
        if (w == 0) return;
        const real F[3] = {w * f(i, 0), w * f(i, 1), w * f(i, 2)};
        const real r[3] = {x(i, 0) - cx, x(i, 1) - cy, x(i, 2) - cz};
        addForceAndMoment(acc, F, r);
      });
}

std::array<double, 6> ParentFrames::bodyLoad(const ExecSpace& exec, int slot, const std::array<double, 3>& centre,
                                             const ConstQuad4View& elementNodes, const ConstRealView& elementPressure,
                                             const ConstIndexView& front, lid_t nInternalFaces,
                                             const ConstReal3View& faceArea, const ConstReal3View& faceCentroid) const {
  const auto W = weights_;
  const int s = slot;
  const real cx = centre[0], cy = centre[1], cz = centre[2];
  return blas::reduce<6>(
      exec, SolverComm{}, "mfsi::coupling::parentFrames::bodyLoad", static_cast<lid_t>(elementNodes.extent(0)),
      KOKKOS_LAMBDA(lid_t e, blas::Sums<6> & acc) {
        real share = 0;
        int nn = 0;
        for (int a = 0; a < 4; ++a) {
          const lid_t v = elementNodes(e, a);
          if (v < 0) continue;
          ++nn;
          share += W(v, s);
        }
        if (share == 0) return;
        const lid_t f = front(e) + nInternalFaces;
        const real w = elementPressure(e) * share / real(nn);
        const real F[3] = {w * faceArea(f, 0), w * faceArea(f, 1), w * faceArea(f, 2)};
        const real r[3] = {faceCentroid(f, 0) - cx, faceCentroid(f, 1) - cy, faceCentroid(f, 2) - cz};
        addForceAndMoment(acc, F, r);
      });
}

}  // namespace mfsi::coupling
