#include "coupling/FluidModule.hpp"

#include "fluid/GhiaTable.hpp"
#include "fluid/Gradient.hpp"
#include "fluid/Loads.hpp"
#include "core/io/HostCopy.hpp"
#include "core/parallel/Gather.hpp"

#include <cmath>
#include <sstream>
#include <type_traits>

namespace mfsi {

using namespace fluid;

namespace {

// The cell among the first n (all: -1) whose centroid (host copy C) is nearest to x, and its
// squared distance.
template <class Centroids>
int nearestCell(const Centroids& C, const Vec3& x, int n = -1, double* distance2 = nullptr) {
  auto dist2 = [&](int i) {
    return (C(i, 0) - x[0]) * (C(i, 0) - x[0]) + (C(i, 1) - x[1]) * (C(i, 1) - x[1]) +
           (C(i, 2) - x[2]) * (C(i, 2) - x[2]);
  };
  if (n < 0) n = static_cast<int>(C.extent(0));
  int best = 0;
  for (int c = 1; c < n; ++c)
    if (dist2(c) < dist2(best)) best = c;
  if (distance2) *distance2 = n > 0 ? dist2(best) : 1e300;
  return best;
}

// Pressure at a point: on a patch, the boundary values of the two nearest faces blended by inverse
// distance (they are extrapolated from the wall cells); otherwise the value of the nearest cell.
double pressureAt(const FluidSolver& fluid, const Vec3& x, const std::string& patch) {
  if (!patch.empty()) return boundaryPressureAt(fluid, patch, x);
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
  return p(nearestCell(C, x));
}

// The same on a decomposed mesh (every rank calls it): the nearest owned cell of every rank, the
// nearest of those (the lowest rank on a tie) giving the value; on a patch, each rank's two nearest
// faces of owned cells, the two nearest of all ranks blended.
double distributedPressureAt(const FluidSolver& fluid, const Vec3& x, const std::string& patch, MPI_Comm comm) {
  const HexMesh& mesh = fluid.mesh();
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (patch.empty()) {
    auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().cellCentroid);
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.pressure());
    double d2 = 1e300;
    const int c = mesh.nOwnedCells() > 0 ? nearestCell(C, x, mesh.nOwnedCells(), &d2) : -1;
    struct {
      double d;
      int rank;
    } mine{d2, rank}, best{0, 0};
    MPI_Allreduce(&mine, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm);
    double v = best.rank == rank && c >= 0 ? p(c) : 0.0, sum = 0;
    MPI_Allreduce(&v, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
    return sum;
  }
  const TwoNearest near = nearestPatchFaces(fluid, patch, x);  // this rank's
  const double mine[4] = {near.d1, near.v1, near.d2, near.v2};
  std::vector<double> all(4 * static_cast<std::size_t>(size));
  MPI_Allgather(mine, 4, MPI_DOUBLE, all.data(), 4, MPI_DOUBLE, comm);
  TwoNearest global;
  for (std::size_t i = 0; i < all.size(); i += 2) global.offer(all[i], all[i + 1]);  // rank order breaks ties
  MFSI_CHECK(!global.empty(), "fluid: pressure at a point: patch '" << patch << "' has no faces");
  return global.blend();
}

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

FluidModule::FluidModule(const HexMesh& mesh, const FluidOptions& options, FluidReports reports,
                         const RankDomain& domain)
    : Module("fluid"),
      solver_(mesh, options, domain),
      reports_(std::move(reports)),
      runaway_(solver_, options.divergenceVelocityFactor) {
  if (options.means.enabled) means_.emplace(mesh.nCells(), options.means);
  if (domain.distributed()) {
    comm_ = domain.comm;
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellGlobalIds());
    ownedIds_.assign(gid.data(), gid.data() + mesh.nOwnedCells());
    long long owned = mesh.nOwnedCells(), all = 0;
    MPI_Allreduce(&owned, &all, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    globalCells_ = static_cast<std::size_t>(all);
  }
  if (reports_.probes.empty()) return;
  // Nearest cell centroids, found once on the mesh as built.
  const std::size_t n = reports_.probes.size();
  probeCells_ = IndexView("mfsi::fluid::probes::cells", n);
  probeValues_ = RealView("mfsi::fluid::probes::values", 4 * n);
  auto C = Kokkos::create_mirror_view_and_copy(HostSpace(), solver_.geometry().cellCentroid);
  auto h = Kokkos::create_mirror_view(probeCells_);
  for (std::size_t i = 0; i < n; ++i) {
    // On a decomposed mesh: the nearest owned cell of each rank; the nearest of those (the lowest
    // rank on a tie) gives the probe's value.
    double d2 = 0;
    h(i) = nearestCell(C, reports_.probes[i].point, comm_ == MPI_COMM_NULL ? -1 : mesh.nOwnedCells(), &d2);
    if (comm_ == MPI_COMM_NULL) continue;
    struct {
      double d;
      int rank;
    } mine{d2, 0}, best{0, 0};
    MPI_Comm_rank(comm_, &mine.rank);
    MPI_Allreduce(&mine, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm_);
    probeOwner_.push_back(best.rank);
  }
  Kokkos::deep_copy(probeCells_, h);
  probePoints_ = Real3View("mfsi::fluid::probes::points", n);
  auto hp = Kokkos::create_mirror_view(probePoints_);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) hp(i, k) = reports_.probes[i].point[k];
  Kokkos::deep_copy(probePoints_, hp);
  probeGradP_ = Real3View("mfsi::fluid::probes::gradP", mesh.nCells());
  probeGradU_ = Tensor3View("mfsi::fluid::probes::gradU", mesh.nCells());
}

std::vector<double> FluidModule::probeValues() const {
  const IndexView cells = probeCells_;
  const RealView values = probeValues_;
  const ConstRealView p = solver_.pressure();
  const ConstReal3View U = solver_.velocity();
  const ExecSpace exec;
  const GradientScheme scheme = solver_.options().gradient;
  cellGradient(exec, scheme, solver_.mesh(), solver_.geometry(), solver_.faceData(), p, solver_.boundaryPressure(),
               probeGradP_, cells);
  cellGradient(exec, scheme, solver_.mesh(), solver_.geometry(), solver_.faceData(), U, solver_.boundaryVelocity(),
               probeGradU_, cells);
  const ConstReal3View gp = probeGradP_, C = solver_.geometry().cellCentroid, X = probePoints_;
  const fluid::ConstTensor3View gu = probeGradU_;
  Kokkos::parallel_for(
      "mfsi::fluid::probes::gather", RangePolicy(exec, 0, static_cast<lid_t>(cells.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        const lid_t c = cells(i);
        const real d[3] = {X(i, 0) - C(c, 0), X(i, 1) - C(c, 1), X(i, 2) - C(c, 2)};
        values(4 * i) = p(c) + gp(c, 0) * d[0] + gp(c, 1) * d[1] + gp(c, 2) * d[2];
        for (int k = 0; k < 3; ++k)
          values(4 * i + 1 + k) = U(c, k) + gu(c, 0, k) * d[0] + gu(c, 1, k) * d[1] + gu(c, 2, k) * d[2];
      });
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), values);
  std::vector<double> v(h.data(), h.data() + h.extent(0));
  if (comm_ != MPI_COMM_NULL) {
    // Each probe's values from the rank that holds it, summed with the others' zeros.
    int rank = 0;
    MPI_Comm_rank(comm_, &rank);
    for (std::size_t i = 0; i < probeOwner_.size(); ++i)
      if (probeOwner_[i] != rank)
        for (int k = 0; k < 4; ++k) v[4 * i + k] = 0.0;
    solver_.comm().globalSum(v.data(), static_cast<int>(v.size()));
  }
  return v;
}

void FluidModule::advance(const TimeState& t) {
  step_ = t;
  last_ = solver_.solveStep(t.time, t.dt);
  account(t);
  endStep();
}

void FluidModule::beginStep(const TimeState& t) {
  step_ = t;
  solver_.beginStep(t.time, t.dt);
}

void FluidModule::endStep() {
  runaway_.check(solver_, step_.time, step_.dt);
  if (means_) means_->accumulate(ExecSpace(), step_.time + step_.dt, step_.dt, solver_.velocity(), solver_.pressure());
}

void FluidModule::solveIteration(const TimeState& t) {
  last_ = solver_.solve();
  account(t);
}

void FluidModule::account(const TimeState& t) {
  outerTotal_ += last_.outerIterations;
  pressureTotal_ += last_.pressureIterations;
  momentumTotal_ += last_.momentumIterations;
  if (!last_.ok || !std::isfinite(last_.continuityMax) || !std::isfinite(last_.finalMomentumResidual))
    throw DivergenceError("fluid: solver breakdown or non-finite fields in the step from t = " + std::to_string(t.time) +
                          " (dt = " + std::to_string(t.dt) + "): reduce the time step or the relaxation factors");
}

std::vector<std::string> FluidModule::stepColumns() const {
  std::vector<std::string> columns = {"outerIterations",  "momentumIterations",   "pressureIterations",
                                      "continuityMax",    "momentumResidual",     "pressureResidual",
                                      "finalMomentumResidual", "finalPressureResidual"};
  for (const auto& p : reports_.probes)
    for (const char* q : {"", ".Ux", ".Uy", ".Uz"}) columns.push_back("probe." + p.name + q);
  for (const auto& f : reports_.forces) {
    for (const char* q : {"force_x", "force_y", "force_z", "moment_x", "moment_y", "moment_z"})
      columns.push_back(f.patch + "." + q);
    if (f.referenceVelocity > 0) {
      columns.push_back(f.patch + ".c_D");
      columns.push_back(f.patch + ".c_L");
    }
  }
  for (const auto& p : reports_.pressureDifferences) columns.push_back(p.name);
  for (const auto& p : reports_.flows) {
    columns.push_back(p + ".flowRate");
    columns.push_back(p + ".pressure");
  }
  if (reports_.meanPressure) {
    // With fluid regions, each fluid's own: the options' fluid, then each region's by its patch.
    columns.push_back("meanPressure");
    for (const fluid::FluidRegion& r : solver_.options().regions) columns.push_back("meanPressure." + r.patch);
  }
  return columns;
}

void FluidModule::appendStepValues(std::vector<double>& v) const {
  v.insert(v.end(), {double(last_.outerIterations), double(last_.momentumIterations), double(last_.pressureIterations),
                     last_.continuityMax, last_.momentumResidual, last_.pressureResidual, last_.finalMomentumResidual,
                     last_.finalPressureResidual});
  if (!reports_.probes.empty()) {
    const std::vector<double> p = probeValues();
    v.insert(v.end(), p.begin(), p.end());
  }
  for (const auto& f : reports_.forces) {
    const PatchLoads L = patchLoads(solver_, f.patch, f.point);
    v.insert(v.end(), {L.force[0], L.force[1], L.force[2], L.moment[0], L.moment[1], L.moment[2]});
    if (f.referenceVelocity > 0) {
      const double q = 0.5 * solver_.options().density * f.referenceVelocity * f.referenceVelocity * f.referenceArea;
      v.push_back(dot(L.force, f.dragDirection) / q);
      v.push_back(dot(L.force, f.liftDirection) / q);
    }
  }
  for (const auto& p : reports_.pressureDifferences) v.push_back(pressureDifference(p.from, p.to, p.patch));
  for (const auto& p : reports_.flows) {
    const PatchFlow f = patchFlow(solver_, p);
    v.insert(v.end(), {f.flowRate, f.meanPressure});
  }
  if (reports_.meanPressure) {
    if (solver_.options().regions.empty()) {
      v.push_back(meanPressure(solver_));
    } else {
      const ConstIndexView fluidOf = solver_.cellFluidIndex();
      v.push_back(meanPressure(solver_, fluidOf, -1));
      for (std::size_t i = 0; i < solver_.options().regions.size(); ++i)
        v.push_back(meanPressure(solver_, fluidOf, static_cast<int>(i)));
    }
  }
}

GhiaErrors FluidModule::ghiaCheck() const {
  const int re = reports_.ghia.re;
  const double lid = reports_.ghia.lidSpeed;
  if (comm_ == MPI_COMM_NULL) return ghiaErrors(solver_, re, lid);
  // Every rank's owned cells gathered on rank 0, which compares; the answer is broadcast.
  const std::size_t n = ownedIds_.size();
  const std::vector<double> c = gatherByGlobalId(comm_, 0, ownedIds_, io::hostValues(solver_.geometry().cellCentroid, n),
                                                 3, globalCells_);
  const std::vector<double> u = gatherByGlobalId(comm_, 0, ownedIds_, io::hostValues(solver_.velocity(), n), 3,
                                                 globalCells_);
  std::array<double, 2> lo, hi;
  planeExtent(solver_.mesh(), lo, hi);
  double ext[4] = {lo[0], lo[1], -hi[0], -hi[1]}, all[4];  // hi negated: one MIN reduction for both
  MPI_Allreduce(ext, all, 4, MPI_DOUBLE, MPI_MIN, comm_);
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);
  GhiaErrors e;
  if (rank == 0) e = ghiaErrors(c, u, {all[0], all[1]}, {-all[2], -all[3]}, re, lid);
  static_assert(std::is_trivially_copyable_v<GhiaErrors>, "broadcast as bytes");
  MPI_Bcast(&e, static_cast<int>(sizeof e), MPI_BYTE, 0, comm_);
  return e;
}

double FluidModule::pressureDifference(const Vec3& from, const Vec3& to, const std::string& patch) const {
  if (comm_ == MPI_COMM_NULL) return pressureAt(solver_, from, patch) - pressureAt(solver_, to, patch);
  return distributedPressureAt(solver_, from, patch, comm_) - distributedPressureAt(solver_, to, patch, comm_);
}

void FluidModule::addOutputFields(io::FieldFrame& frame) {
  io::OutputGrid* grid = frame.find("mesh");
  if (!grid) return;
  // On a decomposed mesh the grid is this rank's part: its owned cells, first in the local order.
  const std::size_t n = static_cast<std::size_t>(comm_ == MPI_COMM_NULL ? solver_.mesh().nCells() : ownedIds_.size());
  grid->addCellField("U", 3, io::hostValues(solver_.velocity(), n));
  grid->addCellField("p", 1, io::hostValues(solver_.pressure(), n));
  if (means_) {
    grid->addCellField("UMean", 3, io::hostValues(means_->velocity(), n));
    grid->addCellField("pMean", 1, io::hostValues(means_->pressure(), n));
  }
}

bool FluidModule::steadyStateReached() const { return solvesSteadyState() && last_.converged; }

bool FluidModule::solvesSteadyState() const { return solver_.options().timeScheme == fluid::TimeScheme::Steady; }

std::string FluidModule::steadyStateGap() const {
  std::ostringstream s;
  s << "fluid: the last SIMPLE iteration's initial residuals, momentum " << last_.finalMomentumResidual
    << " and pressure " << last_.finalPressureResidual << ", are not both below fluid.pimple.outerTolerance "
    << solver_.options().pimple.outerTolerance;
  return s.str();
}

void FluidModule::addMetrics(std::map<std::string, double>& m) const {
  m["fluid.continuity_max"] = last_.continuityMax;
  m["fluid.continuity_sum"] = last_.continuitySum;
  m["fluid.outer_iterations"] = double(outerTotal_);
  m["fluid.momentum_iterations"] = double(momentumTotal_);
  m["fluid.pressure_iterations"] = double(pressureTotal_);
  m["fluid.final_momentum_residual"] = last_.finalMomentumResidual;
  m["fluid.final_pressure_residual"] = last_.finalPressureResidual;
  m["fluid.converged"] = last_.converged ? 1.0 : 0.0;
  m["fluid.max_velocity"] = maxVelocity(solver_);
  if (runaway_.enabled()) m["fluid.velocity_scale"] = runaway_.scale();
  if (means_) m["fluid.means_time"] = means_->averagedTime();
  const double rho = solver_.options().density;
  for (const auto& f : reports_.forces) {
    const PatchLoads L = patchLoads(solver_, f.patch, f.point);
    const std::string k = "fluid." + f.patch + ".";
    const char* xyz[3] = {"x", "y", "z"};
    for (int d = 0; d < 3; ++d) {
      m[k + "force_" + xyz[d]] = L.force[d];
      m[k + "pressure_force_" + xyz[d]] = L.pressureForce[d];
      m[k + "viscous_force_" + xyz[d]] = L.viscousForce[d];
      m[k + "moment_" + xyz[d]] = L.moment[d];
    }
    if (f.referenceVelocity > 0) {
      const double q = 0.5 * rho * f.referenceVelocity * f.referenceVelocity * f.referenceArea;
      m[k + "c_D"] = dot(L.force, f.dragDirection) / q;
      m[k + "c_L"] = dot(L.force, f.liftDirection) / q;
    }
  }
  for (const auto& p : reports_.pressureDifferences) m["fluid." + p.name] = pressureDifference(p.from, p.to, p.patch);
  if (reports_.ghia.enabled) {
    const GhiaErrors e = ghiaCheck();
    m["fluid.ghia_u_max_err"] = e.uMax;
    m["fluid.ghia_v_max_err"] = e.vMax;
    m["fluid.centreline_u_min"] = e.uLineMin;
    m["fluid.centreline_v_min"] = e.vLineMin;
    m["fluid.centreline_v_max"] = e.vLineMax;
  }
}

ModuleEntry fluidModuleEntry() {
  return {"fluid", &fluidSchema, [](const SceneConfig& section, SimulationContext& ctx) {
            if (!ctx.mesh)
              throw InputError(section.where(), "the fluid needs a 'mesh' section (the scene has none)");
            const FluidOptions o = readFluidOptions(section, *ctx.mesh);
            FluidReports r = readFluidReports(section, *ctx.mesh, o);
            std::vector<std::unique_ptr<Module>> v;
            try {
              v.push_back(std::make_unique<FluidModule>(*ctx.mesh, o, std::move(r),
                                                        ctx.domain ? *ctx.domain : RankDomain{}));
            } catch (const InputError& e) {
              // Solver-side checks (inconsistent boundary options) carry no scene location.
              throw InputError(section.where(), e.what());
            }
            return v;
          }};
}

void FluidModule::saveState(io::StateWriter& w) const {
  io::StateWriter s = w.sub("solver");
  solver_.saveState(s);
  const fluid::StepResult& l = last_;
  w.put("lastStep", std::vector<double>{double(l.ok), double(l.converged), double(l.outerIterations),
                                        double(l.momentumIterations), double(l.pressureIterations), l.momentumResidual,
                                        l.pressureResidual, l.finalMomentumResidual, l.finalPressureResidual,
                                        l.continuityMax, l.continuitySum});
  w.put("totals", std::vector<std::int64_t>{outerTotal_, pressureTotal_, momentumTotal_});
  runaway_.saveState(w);
  if (means_) {
    io::StateWriter mw = w.sub("means");
    means_->saveState(mw);
  }
}

void FluidModule::loadState(const io::StateReader& r) {
  solver_.loadState(r.sub("solver"));
  const auto v = r.doubles("lastStep", 11);
  fluid::StepResult& l = last_;
  l.ok = v[0] != 0;
  l.converged = v[1] != 0;
  l.outerIterations = static_cast<int>(v[2]);
  l.momentumIterations = static_cast<int>(v[3]);
  l.pressureIterations = static_cast<int>(v[4]);
  l.momentumResidual = v[5];
  l.pressureResidual = v[6];
  l.finalMomentumResidual = v[7];
  l.finalPressureResidual = v[8];
  l.continuityMax = v[9];
  l.continuitySum = v[10];
  const auto t = r.ints("totals", 3);
  outerTotal_ = t[0];
  pressureTotal_ = t[1];
  momentumTotal_ = t[2];
  runaway_.loadState(r);
  if (means_) means_->loadState(r.sub("means"));
}

}  // namespace mfsi
