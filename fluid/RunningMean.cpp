#include "fluid/RunningMean.hpp"

namespace mfsi::fluid {

RunningMean::RunningMean(lid_t nCells, const RunningMeanOptions& options)
    : options_(options), U_("mfsi::fluid::means::U", nCells), p_("mfsi::fluid::means::p", nCells) {}

bool RunningMean::accumulate(const ExecSpace& exec, real stepEnd, real dt, const ConstReal3View& U,
                             const ConstRealView& p) {
  if (stepEnd < options_.start - 1e-9 * dt) return false;
  total_ += dt;
  // OpenFOAM's fieldAverageItem: beta = dt / T, mean = (1 - beta) mean + beta field.
  const real beta = dt / total_, alpha = 1 - beta;
  auto Um = U_;
  auto pm = p_;
  Kokkos::parallel_for(
      "mfsi::fluid::means::accumulate", RangePolicy(exec, 0, static_cast<lid_t>(pm.extent(0))), KOKKOS_LAMBDA(lid_t c) {
        for (int k = 0; k < 3; ++k) Um(c, k) = alpha * Um(c, k) + beta * U(c, k);
        pm(c) = alpha * pm(c) + beta * p(c);
      });
  return true;
}

void RunningMean::saveState(io::StateWriter& w) const {
  w.putReal("averagedTime", total_);
  w.putView("U", U_, io::Entity::Cells);
  w.putView("p", p_, io::Entity::Cells);
}

void RunningMean::loadState(const io::StateReader& r) {
  total_ = r.real("averagedTime");
  r.getView("U", U_);
  r.getView("p", p_);
}

}  // namespace mfsi::fluid
