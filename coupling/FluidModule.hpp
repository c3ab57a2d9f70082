#pragma once
/// \file
/// \brief The `fluid` section as a module of a run: the incompressible flow solver on the scene
/// mesh, with the reports the scene asks for (patch forces, pressure differences, Ghia check).
#include "coupling/Module.hpp"
#include "fluid/FluidConfig.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/GhiaTable.hpp"
#include "fluid/RunawayGuard.hpp"
#include "fluid/RunningMean.hpp"

#include <optional>

namespace mfsi {

class FluidModule final : public Module {
 public:
  /// Solver on `mesh` (which must outlive the module) with `options`; `reports` name what
  /// addMetrics computes.
  /// On one rank's part of a decomposed mesh `domain` names the ranks: the solver runs
  /// distributed, probes and forces are global, output fields are gathered onto rank 0 (the
  /// pressure-difference and Ghia reports are refused there, not yet distributed).
  FluidModule(const HexMesh& mesh, const fluid::FluidOptions& options, FluidReports reports,
              const RankDomain& domain = {});
  /// One time step (steady: `pimple.outerCorrectors` SIMPLE iterations), then endStep. Throws
  /// DivergenceError when the solver reports a breakdown or non-finite fields, or on runaway growth.
  void advance(const TimeState& t) override;
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  /// The steps of advance, for a module that iterates the fluid within a step (the coupling):
  /// beginStep, then solveIteration once per coupling iteration (PIMPLE on the current mesh and
  /// wall velocities, from the current iterate), then endStep once the step's iterate is final.
  /// solveIteration throws DivergenceError like advance.
  void beginStep(const TimeState& t);
  void solveIteration(const TimeState& t);
  /// The end of the step begun last: the runaway-growth check (fluid.divergenceVelocityFactor;
  /// throws DivergenceError) and the running means (fluid.means).
  void endStep();
  /// fluid.* numbers: continuity, iteration totals, last residuals, max |U| and the velocity scale
  /// of the runaway check, forces, pressure differences, Ghia errors.
  void addMetrics(std::map<std::string, double>& metrics) const override;
  /// Steady (timeScheme steady) and the last step's outer loop converged (outerTolerance).
  bool steadyStateReached() const override;
  bool solvesSteadyState() const override;
  std::string steadyStateGap() const override;
  /// U and p as cell fields of the scene mesh's grid (and UMean, pMean with fluid.means).
  void addOutputFields(io::FieldFrame& frame) override;
  /// Per step: iteration counts and residuals; each probe's p, Ux, Uy, Uz; each force report's
  /// force and moment (and c_D, c_L with a reference velocity); each pressure difference.
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;

  fluid::FluidSolver& solver() { return solver_; }
  const fluid::StepResult& lastStep() const { return last_; }
  const fluid::RunawayGuard& runawayGuard() const { return runaway_; }
  /// The running means (null without fluid.means).
  const fluid::RunningMean* means() const { return means_ ? &*means_ : nullptr; }

  /// The probes' values now: p, Ux, Uy, Uz per probe, each the nearest cell's value corrected by
  /// the cell's gradient to the probe point (second order; a point on a cell face or node, where
  /// the nearest cell is a tie decided by round-off, gets the same value from every candidate).
  /// Public for nvcc: it launches a kernel.
  std::vector<double> probeValues() const;

 private:
  void account(const TimeState& t);  ///< totals and the divergence check of a solve

  fluid::FluidSolver solver_;
  FluidReports reports_;
  IndexView probeCells_;  ///< the cells of reports_.probes
  Real3View probePoints_;
  RealView probeValues_;
  Real3View probeGradP_;             ///< per cell; only the probe cells' rows are computed
  fluid::Tensor3View probeGradU_;
  fluid::StepResult last_;
  TimeState step_;  ///< the step begun last
  fluid::RunawayGuard runaway_;
  std::optional<fluid::RunningMean> means_;
  long long outerTotal_ = 0, pressureTotal_ = 0, momentumTotal_ = 0;
  /// The Ghia comparison, on any rank count (collective when decomposed; every rank gets rank 0's).
  fluid::GhiaErrors ghiaCheck() const;
  /// p(from) - p(to) (on `patch`'s faces when named), on any rank count (collective when decomposed).
  double pressureDifference(const fluid::Vec3& from, const fluid::Vec3& to, const std::string& patch) const;
  /// A decomposed mesh: the ranks, the owned cells' global ids, the whole mesh's cell count, and
  /// the rank whose nearest cell holds each probe.
  MPI_Comm comm_ = MPI_COMM_NULL;
  std::vector<gid_t> ownedIds_;
  std::size_t globalCells_ = 0;
  std::vector<int> probeOwner_;
};

/// Catalogue entry of the `fluid` section (needs the scene's `mesh`).
ModuleEntry fluidModuleEntry();

}  // namespace mfsi
