#pragma once
/// \file
/// \brief The `membranes` section as modules of a run: one module per panel, named "membrane"
/// (a single unnamed panel), "membrane.<name>" or "membrane.<index>".
///
/// Static analysis: equilibrium under the loads at t = 0 when the run starts (openOutput), then at
/// the end time of every step (time functions of the loads make a load ramp). Dynamic analysis:
/// one implicit step per run step from the initial shape. Either throws DivergenceError when a
/// solve does not converge or the state is not finite.
#include "coupling/Module.hpp"
#include "structure/membrane/MembraneConfig.hpp"
#include "structure/membrane/MembraneMeshImport.hpp"
#include "structure/membrane/MembraneSolver.hpp"

#include <memory>
#include <optional>

namespace mfsi {

class MembraneModule final : public Module {
 public:
  explicit MembraneModule(const MembranePanelOptions& options);

  void advance(const TimeState& t) override;
  /// The solver's state (MembraneSolver::saveState) under "solver", whether a static panel has
  /// been solved (a restarted run must not solve t = 0 again), the sampled values of steps.csv and
  /// the centre-deflection history of the period estimate.
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  /// "<name>.<summary key>" for every entry of MembraneSolver::summary(), and the comparison with
  /// the reference solution: hencky_w0 (computed), hencky_w0_exact and hencky_rel_err, or period, period_exact and
  /// period_rel_err.
  void addMetrics(std::map<std::string, double>& metrics) const override;
  /// A grid of its own: the deformed surface (reference + displacement), displacement and velocity
  /// per node; per element the in-plane Green-Lagrange strain and PK2 stress (E11, E22, E12 and
  /// S11, S22, S12 in the element basis), principal stresses, von Mises and the wrinkling state
  /// (0 taut, 1 wrinkled, 2 slack).
  void addOutputFields(io::FieldFrame& frame) override;
  /// Solves the t = 0 equilibrium of a static panel (the run is starting).
  void openOutput(const std::string& dir, const OutputStart& start) override;
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;

  MembraneSolver& solver() { return *solver_; }
  const MembraneSolver& solver() const { return *solver_; }
  /// Re-read max |u| and the centre deflection of the current state (after another module moved
  /// it, e.g. the coupling's commit). Throws DivergenceError on a non-finite displacement.
  void sampleState() { sample(); }
  const MembranePanelOptions& panel() const { return panel_; }
  /// The fluid-mesh surface the membrane was cut from (baffle or boundary patch: its node and face
  /// maps); null for other meshes.
  const FluidSurfaceMembraneInput* fluidSurface() const { return surface_ ? &*surface_ : nullptr; }

 private:
  void check(const MembraneSolveReport& report, const char* what, double time);
  void sample();  ///< max |u| and centre deflection of the current state

  MembranePanelOptions panel_;
  std::optional<FluidSurfaceMembraneInput> surface_;
  std::unique_ptr<MembraneSolver> solver_;
  lid_t centre_ = 0;
  std::array<real, 3> centreNormal_{0, 0, 1};
  bool solved_ = false;
  real maxU_ = 0;
  real centreW_ = 0;
  std::array<real, 3> centreU_{0, 0, 0};  ///< displacement of the centre node
  std::vector<double> history_;  ///< centre deflection at t = 0, dt, 2 dt, ... (dynamic)
  double dt_ = 0;
};

/// Catalogue entry of the `membranes` section.
ModuleEntry membraneModuleEntry();

}  // namespace mfsi
