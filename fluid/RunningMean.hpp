#pragma once
/// \file
/// \brief Running time means of the cell velocity and pressure (the `fluid.means` scene key),
/// accumulated once per step as OpenFOAM's fieldAverage does for its mean:
///   T += dt;  mean = (1 - dt / T) mean + (dt / T) field,
/// so after steps 1..n that entered, mean = sum_i dt_i field_i / sum_i dt_i (the first step that
/// enters sets mean = field exactly). The field of a step is its value at the step's end, as a
/// function object executed at the end of each time step sees it.
#include "core/io/Checkpoint.hpp"
#include "fluid/FluidOptions.hpp"

namespace mfsi::fluid {

/// \brief Time means of a cell vector and a cell scalar field (Views `mfsi::fluid::means::*`).
class RunningMean {
 public:
  /// \brief Means of `nCells` cells from `options.start` on, zero until a step enters.
  RunningMean(lid_t nCells, const RunningMeanOptions& options);

  /// \brief The fields `U`, `p` at the end of the step from `stepEnd - dt` to `stepEnd` enter with
  /// weight dt when stepEnd >= start (with a round-off allowance of 1e-9 dt). Returns whether they did.
  bool accumulate(const ExecSpace& exec, real stepEnd, real dt, const ConstReal3View& U, const ConstRealView& p);

  /// Mean velocity [m/s] per cell.
  ConstReal3View velocity() const { return U_; }
  /// Mean pressure [Pa] per cell.
  ConstRealView pressure() const { return p_; }
  /// T: the time averaged so far [s] (0 before the first step that entered).
  real averagedTime() const { return total_; }
  const RunningMeanOptions& options() const { return options_; }

  /// \brief The means and T, bitwise, for a checkpoint.
  void saveState(io::StateWriter& w) const;
  void loadState(const io::StateReader& r);

 private:
  RunningMeanOptions options_;
  Real3View U_;
  RealView p_;
  real total_ = 0;
};

}  // namespace mfsi::fluid
