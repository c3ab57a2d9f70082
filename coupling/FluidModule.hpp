#pragma once
/// \file
/// \brief The `fluid` section as a module of a run: the incompressible flow solver on the scene
/// mesh, with the reports the scene asks for (patch forces, pressure differences, Ghia check).
#include "coupling/Module.hpp"
#include "fluid/FluidConfig.hpp"
#include "fluid/FluidSolver.hpp"

namespace mfsi {

class FluidModule final : public Module {
 public:
  /// Solver on `mesh` (which must outlive the module) with `options`; `reports` name what
  /// addMetrics computes.
  FluidModule(const HexMesh& mesh, const fluid::FluidOptions& options, FluidReports reports);
  /// One time step (steady: `pimple.outerCorrectors` SIMPLE iterations). Throws DivergenceError
  /// when the solver reports a breakdown or non-finite fields.
  void advance(const TimeState& t) override;
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  /// The steps of advance, for a module that iterates the fluid within a step (the coupling):
  /// beginStep, then solveIteration once per coupling iteration (PIMPLE on the current mesh and
  /// wall velocities, from the current iterate). solveIteration throws DivergenceError like advance.
  void beginStep(const TimeState& t);
  void solveIteration(const TimeState& t);
  void endStep() {}
  /// fluid.* numbers: continuity, iteration totals, last residuals, forces, pressure differences,
  /// Ghia errors.
  void addMetrics(std::map<std::string, double>& metrics) const override;
  /// U and p as cell fields of the scene mesh's grid.
  void addOutputFields(io::FieldFrame& frame) override;
  /// Per step: iteration counts and residuals; each probe's p, Ux, Uy, Uz; each force report's
  /// force and moment (and c_D, c_L with a reference velocity); each pressure difference.
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;

  fluid::FluidSolver& solver() { return solver_; }
  const fluid::StepResult& lastStep() const { return last_; }

  /// The probes' cell values now: p, Ux, Uy, Uz per probe (public for nvcc: it launches a kernel).
  std::vector<double> probeValues() const;

 private:
  void account(const TimeState& t);  ///< totals and the divergence check of a solve

  fluid::FluidSolver solver_;
  FluidReports reports_;
  IndexView probeCells_;  ///< the cells of reports_.probes
  RealView probeValues_;
  fluid::StepResult last_;
  long long outerTotal_ = 0, pressureTotal_ = 0, momentumTotal_ = 0;
};

/// Catalogue entry of the `fluid` section (needs the scene's `mesh`).
ModuleEntry fluidModuleEntry();

}  // namespace mfsi
