#include "structure/membrane/MembraneOptions.hpp"

#include "core/Error.hpp"

#include <cmath>

namespace mfsi {

void validate(const MembraneMaterial& m) {
  MFSI_CHECK(m.youngsModulus > 0, "membrane material: youngsModulus must be > 0, got " << m.youngsModulus);
  MFSI_CHECK(m.poissonRatio >= 0 && m.poissonRatio <= 0.5,
             "membrane material: poissonRatio must be in [0, 0.5], got " << m.poissonRatio);
  MFSI_CHECK(m.thickness > 0, "membrane material: thickness must be > 0, got " << m.thickness);
  MFSI_CHECK(m.density >= 0, "membrane material: density must be >= 0, got " << m.density);
}

const char* toString(MembraneWrinklingModel model) {
  return model == MembraneWrinklingModel::None ? "none" : "tensionField";
}
const char* toString(MembraneWrinkleState state) {
  switch (state) {
    case MembraneWrinkleState::Taut: return "taut";
    case MembraneWrinkleState::Wrinkled: return "wrinkled";
    case MembraneWrinkleState::Slack: return "slack";
  }
  return "?";
}
const char* toString(MembraneStaticSolver v) {
  return v == MembraneStaticSolver::Newton ? "newton" : "lumpedNewtonRaphson";
}
const char* toString(MembranePressureDirection v) {
  return v == MembranePressureDirection::Follower ? "follower" : "dead";
}
const char* toString(MembraneTimeIntegrator v) {
  return v == MembraneTimeIntegrator::Newmark ? "newmark" : "generalizedAlpha";
}

std::array<real, 3> MembraneRigidTransform::apply(const std::array<real, 3>& X) const {
  std::array<real, 3> x{};
  for (int i = 0; i < 3; ++i) {
    x[i] = origin[i] + translation[i];
    for (int j = 0; j < 3; ++j) x[i] += rotation[i][j] * (X[j] - origin[j]);
  }
  return x;
}

MembraneRigidTransform MembraneRigidTransform::rotationAbout(const std::array<real, 3>& axis, real angle,
                                                             const std::array<real, 3>& origin) {
  const real l = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  MFSI_CHECK(l > 0, "rotation axis must be non-zero");
  const real k[3] = {axis[0] / l, axis[1] / l, axis[2] / l};
  const real c = std::cos(angle), s = std::sin(angle);
  MembraneRigidTransform t;
  t.origin = origin;
  // Rodrigues: R = c I + s [k]x + (1 - c) k k^T.
  const real K[3][3] = {{0, -k[2], k[1]}, {k[2], 0, -k[0]}, {-k[1], k[0], 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.rotation[i][j] = (i == j ? c : 0) + s * K[i][j] + (1 - c) * k[i] * k[j];
  return t;
}

std::vector<MembraneEdgeBeam> makeEdgeBeams(const std::vector<lid_t>& chain, real axialStiffness, bool closed,
                                            bool tensionOnly) {
  std::vector<MembraneEdgeBeam> out;
  for (std::size_t i = 0; i + 1 < chain.size(); ++i) out.push_back({chain[i], chain[i + 1], axialStiffness, tensionOnly});
  if (closed && chain.size() > 2) out.push_back({chain.back(), chain.front(), axialStiffness, tensionOnly});
  return out;
}

}  // namespace mfsi
