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

std::vector<MembraneEdgeBeam> makeEdgeBeams(const std::vector<lid_t>& chain, real axialStiffness, bool closed,
                                            bool tensionOnly) {
  std::vector<MembraneEdgeBeam> out;
  for (std::size_t i = 0; i + 1 < chain.size(); ++i) out.push_back({chain[i], chain[i + 1], axialStiffness, tensionOnly});
  if (closed && chain.size() > 2) out.push_back({chain.back(), chain.front(), axialStiffness, tensionOnly});
  return out;
}

}  // namespace mfsi
