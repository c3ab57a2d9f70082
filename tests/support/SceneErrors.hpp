#pragma once
/// \file
/// \brief The InputError a scene (with `--set` overrides) raises when it is built: "" when none.
#include "core/Error.hpp"
#include "coupling/Module.hpp"
#include "coupling/Simulation.hpp"

#include <string>
#include <vector>

namespace mfsi::test {

inline std::string sceneInputError(const std::string& scene, const std::vector<std::string>& sets) {
  try {
    auto cfg = mfsi::SceneConfig::load(scene, mfsi::sceneSchema(), sets);
    mfsi::Simulation sim(cfg);
  } catch (const mfsi::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace mfsi::test
