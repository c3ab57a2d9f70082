#include "coupling/Module.hpp"

#include "coupling/FluidModule.hpp"
#include "coupling/MembraneModule.hpp"
#include "coupling/RigidModule.hpp"
#include "coupling/orchestrator/FsiCoupling.hpp"

namespace mfsi {

namespace {
std::map<std::string, int>& counts() {
  static std::map<std::string, int> c;
  return c;
}
}  // namespace

Module::Module(std::string name) : name_(std::move(name)) { ++counts()[name_]; }

const std::map<std::string, int>& Module::constructionCounts() { return counts(); }

const std::vector<ModuleEntry>& moduleCatalogue() {
  // Physics modules register here as they land. The coupling comes last: it takes the modules it
  // composes from those built before it.
  static const std::vector<ModuleEntry> catalogue = {fluidModuleEntry(), membraneModuleEntry(), rigidModuleEntry(),
                                                     couplingModuleEntry()};
  return catalogue;
}

}  // namespace mfsi
