#include "fluid/RunawayGuard.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace mfsi::fluid {

namespace {

/// Bounds [lo, hi] of f(t) over all t; false when they are not known (a function of t).
bool timeFunctionRange(const TimeFunction& f, real& lo, real& hi) {
  switch (f.kind) {
    case TimeFunction::Kind::Constant:
      lo = hi = 1;
      return true;
    case TimeFunction::Kind::OneMinusCos:
      lo = 0, hi = 2;
      return true;
    case TimeFunction::Kind::CosineRamp:
    case TimeFunction::Kind::HalfPowerSine:
      lo = 0, hi = 1;
      return true;
    case TimeFunction::Kind::Function:
      return false;
  }
  return false;
}

real norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/// Peak over mean of a flow-rate profile: prod over its axes of 1.5 (parabolic) or 2 (linear).
real peakToMean(const PatchBC& bc) {
  if (bc.profile != Profile::Parabolic && bc.profile != Profile::Linear) return 1;
  real r = 1;
  for (int d = 0; d < 3; ++d)
    if (bc.parabolicAxes[d]) r *= bc.profile == Profile::Parabolic ? 1.5 : 2.0;
  return r;
}

real pressureScale(real lo, real hi, real rho) { return hi > lo ? std::sqrt(2 * (hi - lo) / rho) : 0.0; }

}  // namespace

real PrescribedVelocityScale::value() const { return std::max({boundary, initial, pressure, gravity}); }

PrescribedVelocityScale prescribedVelocityScale(const FluidSolver& fluid) {
  const FluidOptions& o = fluid.options();
  PrescribedVelocityScale s;
  s.initial = norm(o.initialVelocity);
  auto area = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().faceAreaMag);
  real pLo = o.initialPressure, pHi = o.initialPressure;
  for (const ResolvedPatch& rp : fluid.boundaryConditions().patches()) {
    real lo = 1, hi = 1;
    if (!timeFunctionRange(rp.bc.timeFunction, lo, hi)) continue;  // evaluated values only (check)
    const real peak = std::max(std::abs(lo), std::abs(hi));
    switch (rp.type) {
      case BoundaryType::FixedVelocity:
        if (rp.bc.profile != Profile::Function) s.boundary = std::max(s.boundary, peak * norm(rp.bc.velocity));
        break;
      case BoundaryType::FlowRate: {
        real a = 0;
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) a += area(f);
        if (a > 0) s.boundary = std::max(s.boundary, peak * std::abs(rp.bc.flowRate) / a * peakToMean(rp.bc));
        break;
      }
      case BoundaryType::Wall:
        if (rp.bc.wallMotion == WallMotion::Fixed) s.boundary = std::max(s.boundary, peak * norm(rp.bc.velocity));
        break;
      case BoundaryType::FixedPressure:
      case BoundaryType::Resistance:  // its p0; the part R q only resists the flow
        pLo = std::min({pLo, lo * rp.bc.pressure, hi * rp.bc.pressure});
        pHi = std::max({pHi, lo * rp.bc.pressure, hi * rp.bc.pressure});
        break;
      default:
        break;
    }
  }
  s.pressure = pressureScale(pLo, pHi, o.density);
  const real g = norm(o.bodyForce);
  if (g > 0) {
    auto P = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.mesh().referencePoints());
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    for (int n = 0; n < static_cast<int>(P.extent(0)); ++n)
      for (int d = 0; d < 3; ++d) {
        lo[d] = n == 0 ? P(n, d) : std::min(lo[d], P(n, d));
        hi[d] = n == 0 ? P(n, d) : std::max(hi[d], P(n, d));
      }
    for (int d = 0; d < 3; ++d) {  // the whole mesh's box on a decomposed one
      lo[d] = -fluid.comm().globalMax(-lo[d]);
      hi[d] = fluid.comm().globalMax(hi[d]);
    }
    const real L = norm({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    s.gravity = std::sqrt(2 * g * L);
  }
  return s;
}

real boundaryVelocityNow(const FluidSolver& fluid) {
  const BoundaryConditions& bc = fluid.boundaryConditions();
  ConstIndexView kind = bc.kind();
  ConstReal3View ub = bc.velocity(), um = fluid.boundaryMeshVelocity();
  real m2 = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::runaway::boundary", RangePolicy(ExecSpace(), 0, static_cast<lid_t>(kind.extent(0))),
      KOKKOS_LAMBDA(lid_t b, real & m) {
        const bool prescribed = kind(b) == kFaceVelocity || kind(b) == kFaceWall;
        const real u2 = prescribed ? ub(b, 0) * ub(b, 0) + ub(b, 1) * ub(b, 1) + ub(b, 2) * ub(b, 2) : 0.0;
        const real w2 = um(b, 0) * um(b, 0) + um(b, 1) * um(b, 1) + um(b, 2) * um(b, 2);
        const real v = u2 > w2 ? u2 : w2;
        m = v > m ? v : m;
      },
      Kokkos::Max<real>(m2));
  return std::sqrt(fluid.comm().globalMax(m2));
}

real maxVelocity(const FluidSolver& fluid) {
  ConstReal3View U = fluid.velocity();
  real m2 = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::maxVelocity", RangePolicy(ExecSpace(), 0, fluid.ownedCells()),
      KOKKOS_LAMBDA(lid_t c, real & m) {
        const real v = U(c, 0) * U(c, 0) + U(c, 1) * U(c, 1) + U(c, 2) * U(c, 2);
        m = v > m ? v : m;
      },
      Kokkos::Max<real>(m2));
  return std::sqrt(fluid.comm().globalMax(m2));
}

RunawayGuard::RunawayGuard(const FluidSolver& fluid, real factor)
    : factor_(factor), prescribed_(prescribedVelocityScale(fluid)) {}

real RunawayGuard::scale() const { return std::max(prescribed_.value(), boundarySeen_); }

void RunawayGuard::check(const FluidSolver& fluid, real time, real dt) {
  if (!enabled()) return;
  real now = boundaryVelocityNow(fluid);
  // Prescribed pressures as evaluated this step: time functions given as functions of t.
  const FluidOptions& o = fluid.options();
  real pLo = o.initialPressure, pHi = o.initialPressure;
  for (const ResolvedPatch& rp : fluid.boundaryConditions().patches())
    if (rp.type == BoundaryType::FixedPressure) {
      pLo = std::min(pLo, rp.currentPressure);
      pHi = std::max(pHi, rp.currentPressure);
    }
  now = std::max(now, pressureScale(pLo, pHi, o.density));
  boundarySeen_ = std::max(boundarySeen_, now);
  lastMax_ = maxVelocity(fluid);
  const real s = scale();
  if (s > 0 && !(lastMax_ <= factor_ * s)) {
    std::ostringstream os;
    os << "fluid: runaway growth in the step to t = " << time + dt << " (dt = " << dt << "): max |U| = " << lastMax_
       << " m/s exceeds fluid.divergenceVelocityFactor = " << factor_ << " times the velocity scale " << s
       << " m/s of the boundary conditions (the largest of:";
    const std::pair<const char*, real> parts[] = {{"prescribed velocities", prescribed_.boundary},
                                                  {"initial velocity", prescribed_.initial},
                                                  {"pressure differences", prescribed_.pressure},
                                                  {"gravity", prescribed_.gravity},
                                                  {"boundary velocities so far", boundarySeen_}};
    const char* sep = " ";
    for (const auto& [name, v] : parts) {
      if (!(v > 0)) continue;
      os << sep << name << " " << v;
      sep = ", ";
    }
    os << "): the solution is growing without bound; reduce time.dt, "
       << "under-relax (fluid.pimple.relaxVelocity, relaxPressure) or add outer correctors (fluid.pimple."
       << "outerCorrectors); if such velocities are expected, raise the factor (0 switches the check off)";
    throw DivergenceError(os.str());
  }
}

void RunawayGuard::saveState(io::StateWriter& w) const {
  w.put("runaway", std::vector<double>{boundarySeen_, lastMax_});
}

void RunawayGuard::loadState(const io::StateReader& r) {
  const auto v = r.doubles("runaway", 2);
  boundarySeen_ = v[0];
  lastMax_ = v[1];
}

}  // namespace mfsi::fluid
