#include "coupling/MembraneModule.hpp"

#include "core/io/HostCopy.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi {

namespace {
const double kPi = std::acos(-1.0);

/// Mean period from the zero crossings (linear interpolation) of a signal sampled every dt; 0
/// with fewer than three crossings.
double periodFromZeroCrossings(const std::vector<double>& w, double dt) {
  std::vector<double> t;
  for (std::size_t k = 0; k + 1 < w.size(); ++k)
    if ((w[k] > 0) != (w[k + 1] > 0)) t.push_back(dt * (k + w[k] / (w[k] - w[k + 1])));
  if (t.size() < 3) return 0;
  return 2 * (t.back() - t.front()) / (t.size() - 1);
}
}  // namespace

MembraneModule::MembraneModule(const MembranePanelOptions& options) : Module(options.name), panel_(options) {
  // A membrane cut from the fluid mesh keeps the maps of its surface for the coupling (on several
  // ranks the options hold it, cut by the rank that holds it).
  if (panel_.mesh.surface)
    surface_ = *panel_.mesh.surface;
  else if (panel_.mesh.kind == MembraneMeshKind::Baffle)
    surface_ = membraneMeshFromBaffle(*panel_.mesh.fluidMesh, panel_.mesh.baffle);
  else if (panel_.mesh.kind == MembraneMeshKind::Patch)
    surface_ = membraneMeshFromPatch(*panel_.mesh.fluidMesh, panel_.mesh.patch);
  const MembraneMesh mesh = buildMembraneMesh(surface_ ? surface_->mesh : generateMembraneMesh(panel_.mesh));
  solver_ = std::make_unique<MembraneSolver>(mesh, panel_.options, resolveMembraneBoundary(panel_.boundary, mesh),
                                             panel_.loads);
  centre_ =
      mesh.hasNodeSet("centre") && !mesh.nodeSet("centre").empty() ? mesh.nodeSet("centre").front() : mesh.centreNode();
  centreNormal_ = mesh.hostNodeNormals()[centre_];

  const MembraneInitialSpec& init = panel_.initial;
  if (init.shape == MembraneInitialShape::SineMode) {
    // w = A sin(m pi x / lx) sin(n pi y / ly) along the normal (+z) of the flat rectangle.
    const MembraneRectangleSpec& r = panel_.mesh.rectangle;
    auto u = Kokkos::create_mirror_view(solver_->displacement());
    Kokkos::deep_copy(u, 0.0);
    for (lid_t i = 0; i < mesh.nNodes(); ++i) {
      const auto& X = mesh.hostPoints()[i];
      u(3 * i + 2) = init.amplitude * std::sin(init.mode[0] * kPi * (X[0] - r.origin[0]) / r.lx) *
                     std::sin(init.mode[1] * kPi * (X[1] - r.origin[1]) / r.ly);
    }
    Kokkos::deep_copy(solver_->displacement(), u);
    solver_->resetDynamics();
  }
  sample();
}

void MembraneModule::sample() {
  const auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), solver_->displacement());
  const lid_t n = static_cast<lid_t>(u.extent(0) / 3);
  real m2 = 0;
  bool finite = true;
  for (lid_t i = 0; i < n; ++i) {
    const real a = u(3 * i) * u(3 * i) + u(3 * i + 1) * u(3 * i + 1) + u(3 * i + 2) * u(3 * i + 2);
    finite = finite && std::isfinite(a);
    m2 = std::max(m2, a);
  }
  if (!finite) throw DivergenceError(name() + ": non-finite displacement at t = " + std::to_string(solver_->time()));
  maxU_ = std::sqrt(m2);
  centreW_ = 0;
  for (int k = 0; k < 3; ++k) {
    centreU_[k] = u(3 * centre_ + k);
    centreW_ += centreU_[k] * centreNormal_[k];
  }
}

void MembraneModule::check(const MembraneSolveReport& report, const char* what, double time) {
  if (!report.converged || !std::isfinite(report.relativeResidual))
    throw DivergenceError(name() + ": " + what + " did not converge at t = " + std::to_string(time) + " (" +
                          std::to_string(report.iterations) + " iterations, relative residual " +
                          std::to_string(report.relativeResidual) + ")");
  sample();
}

void MembraneModule::openOutput(const std::string& /*dir*/, const OutputStart& /*start*/) {
  if (panel_.analysis != MembraneAnalysis::Static || solved_) return;
  check(solver_->solveStatic(0), "static solve", 0);
  solved_ = true;
}

void MembraneModule::advance(const TimeState& t) {
  if (panel_.analysis == MembraneAnalysis::Static) {
    check(solver_->solveStatic(t.time + t.dt), "static solve", t.time + t.dt);
    solved_ = true;
    return;
  }
  if (history_.empty()) {
    history_.push_back(centreW_);
    dt_ = t.dt;
  }
  solver_->setTime(t.time);
  check(solver_->step(t.dt), "time step", t.time + t.dt);
  // The period estimate assumes equal steps; a shorter last step ends the sampled record.
  if (std::abs(t.dt - dt_) <= 1e-12 * dt_) history_.push_back(centreW_);
}

std::vector<std::string> MembraneModule::stepColumns() const {
  return {"iterations", "residual", "maxDisplacement", "centreDeflection", "centreUx", "centreUy", "centreUz"};
}

void MembraneModule::appendStepValues(std::vector<double>& values) const {
  const MembraneSolveReport& r = solver_->lastReport();
  values.push_back(r.iterations);
  values.push_back(r.relativeResidual);
  values.push_back(maxU_);
  values.push_back(centreW_);
  values.insert(values.end(), {centreU_[0], centreU_[1], centreU_[2]});
}

void MembraneModule::addOutputFields(io::FieldFrame& frame) {
  const MembraneMesh& mesh = solver_->mesh();
  const std::size_t nNodes = static_cast<std::size_t>(mesh.nNodes());
  const std::size_t nElements = static_cast<std::size_t>(mesh.nElements());
  io::OutputGrid g;
  g.name = name();
  g.shape = io::CellShape::Surface;
  const std::vector<double> u = io::hostValues(solver_->displacement(), 3 * nNodes);
  for (std::size_t i = 0; i < nNodes; ++i)
    for (int k = 0; k < 3; ++k) g.points.push_back(mesh.hostPoints()[i][k] + u[3 * i + k]);
  for (const auto& e : mesh.hostElements())
    for (int a = 0; a < 4; ++a) g.cells.push_back(e[a]);
  g.addPointField("displacement", 3, u);
  g.addPointField("velocity", 3, io::hostValues(solver_->velocity(), 3 * nNodes));
  const MembraneResults r = solver_->results();
  g.addCellField("strain", 3, io::hostValues(r.elements.strain, nElements), false);
  g.addCellField("stress", 3, io::hostValues(r.elements.stress, nElements), false);
  g.addCellField("principalStress1", 1, io::hostValues(r.elements.principal1, nElements));
  g.addCellField("principalStress2", 1, io::hostValues(r.elements.principal2, nElements));
  g.addCellField("vonMises", 1, io::hostValues(r.elements.vonMises, nElements));
  g.addCellField("wrinkleState", 1, io::hostValues(r.elements.wrinkleState, nElements));
  frame.grids.push_back(std::move(g));
}

void MembraneModule::addMetrics(std::map<std::string, double>& metrics) const {
  const std::string p = name() + ".";
  for (const auto& [k, v] : solver_->summary()) metrics[p + k] = v;
  metrics[p + "centreUx"] = centreU_[0];
  metrics[p + "centreUy"] = centreU_[1];
  metrics[p + "centreUz"] = centreU_[2];
  const MembraneMaterial& m = panel_.options.material;
  if (panel_.reference == MembraneReference::Hencky) {
    // Hencky: w0 = C_w(nu) a (p a / (E h))^(1/3), along the load.
    const double a = panel_.mesh.disc.radius;
    const double p0 =
        panel_.loads.pressure * (panel_.loads.pressureTime ? panel_.loads.pressureTime(solver_->time()) : 1);
    const double exact = henckyCoefficient(m.poissonRatio) * a * std::cbrt(p0 * a / (m.youngsModulus * m.thickness));
    metrics[p + "hencky_w0"] = centreW_;  // computed, like period against period_exact
    metrics[p + "hencky_w0_exact"] = exact;
    if (exact != 0) metrics[p + "hencky_rel_err"] = std::abs(centreW_ - exact) / std::abs(exact);
  } else if (panel_.reference == MembraneReference::SquareFrequency) {
    const MembraneRectangleSpec& r = panel_.mesh.rectangle;
    const double f = rectangleMembraneFrequency(m.preStress, m.density * m.thickness, r.lx, r.ly,
                                                panel_.initial.mode[0], panel_.initial.mode[1]);
    const double period = periodFromZeroCrossings(history_, dt_);
    metrics[p + "period_exact"] = 1 / f;
    if (period > 0) {
      metrics[p + "period"] = period;
      metrics[p + "period_rel_err"] = std::abs(period * f - 1);
    }
  }
}

ModuleEntry membraneModuleEntry() {
  return {"membranes", &membraneSchema, [](const SceneConfig& section, SimulationContext& ctx) {
            std::vector<std::unique_ptr<Module>> v;
            const MPI_Comm comm = ctx.domain != nullptr ? ctx.domain->comm : MPI_COMM_NULL;
            for (const auto& panel : readMembraneOptions(section, ctx.mesh, comm))
              v.push_back(std::make_unique<MembraneModule>(panel));
            return v;
          }};
}

void MembraneModule::saveState(io::StateWriter& w) const {
  io::StateWriter solver = w.sub("solver");
  solver_->saveState(solver);
  w.putBool("solved", solved_);
  w.putReal("maxDisplacement", maxU_);
  w.putReal("centreDeflection", centreW_);
  w.put("centreDisplacement", std::vector<double>(centreU_.begin(), centreU_.end()));
  w.put("history", history_);
  w.putReal("dt", dt_);
}

void MembraneModule::loadState(const io::StateReader& r) {
  solver_->loadState(r.sub("solver"));
  solved_ = r.boolean("solved");
  maxU_ = r.real("maxDisplacement");
  centreW_ = r.real("centreDeflection");
  const std::vector<double> c = r.doubles("centreDisplacement", 3);
  std::copy(c.begin(), c.end(), centreU_.begin());
  history_ = r.doubles("history");
  dt_ = r.real("dt");
}

}  // namespace mfsi
