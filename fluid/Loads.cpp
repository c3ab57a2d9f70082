#include "fluid/Loads.hpp"

#include "core/Error.hpp"

#include <cmath>

namespace mfsi::fluid {

namespace {

void tractionRange(const FluidSolver& fluid, lid_t start, lid_t size, const Real3View& tp, const Real3View& tv) {
  const HexMesh& mesh = fluid.mesh();
  const lid_t nIn = mesh.nInternalFaces();
  const real mu = fluid.options().viscosity;
  ConstRealView muC = fluid.cellViscosity();  // empty: every cell's is mu
  const bool perCell = muC.extent(0) > 0;
  ConstIndexView own = mesh.faceOwner();
  ConstReal3View sf = fluid.geometry().faceArea;
  ConstRealView sm = fluid.geometry().faceAreaMag;
  ConstRealView nd = fluid.faceData().normalDist;
  ConstReal3View U = fluid.velocity(), Ub = fluid.boundaryVelocity();
  ConstRealView pb = fluid.boundaryPressure();
  ConstTensor3View G = fluid.velocityGradient();
  Kokkos::parallel_for(
      "mfsi::fluid::loads::traction", RangePolicy(ExecSpace(), 0, size), KOKKOS_LAMBDA(lid_t i) {
        const lid_t f = start + i, b = f - nIn, o = own(f);
        const real n[3] = {sf(f, 0) / sm(f), sf(f, 1) / sm(f), sf(f, 2) / sm(f)};
        for (int k = 0; k < 3; ++k) {
          const real dudn = (Ub(b, k) - U(o, k)) / nd(f);
          real tr = 0;
          for (int j = 0; j < 3; ++j) tr += G(o, k, j) * n[j];
          tp(i, k) = pb(b) * n[k];
          tv(i, k) = -(perCell ? muC(o) : mu) * (dudn + tr);
        }
      });
}

}  // namespace

void boundaryTraction(const FluidSolver& fluid, const std::string& patch, const Real3View& pressureTraction,
                      const Real3View& viscousTraction) {
  const int idx = fluid.mesh().patchIndex(patch);
  const auto& p = fluid.mesh().patches()[idx];
  MFSI_CHECK(static_cast<lid_t>(pressureTraction.extent(0)) == p.size &&
                 static_cast<lid_t>(viscousTraction.extent(0)) == p.size,
             "fluid: boundaryTraction: patch '" << patch << "' has " << p.size << " faces");
  tractionRange(fluid, p.start, p.size, pressureTraction, viscousTraction);
}

PatchLoads patchLoads(const FluidSolver& fluid, const std::string& name, const Vec3& point) {
  const auto idx = fluid.boundaryConditions().find(name);
  MFSI_CHECK(!idx.empty(), "fluid: patchLoads: no patch or baffle named '" << name << "'");
  (void)fluid.velocityGradient();  // formed on every rank (it exchanges ghosts), with or without faces here
  PatchLoads out;
  ConstRealView sm = fluid.geometry().faceAreaMag;
  ConstReal3View fc = fluid.geometry().faceCentroid;
  ConstIndexView own = fluid.mesh().faceOwner();
  // On a decomposed mesh a ghost cell's patch faces are its owner rank's: counted there.
  const lid_t nOwned = fluid.ownedCells();
  for (int i : idx) {
    const auto& p = fluid.mesh().patches()[i];
    // A rank without faces of the patch still takes part in the sum over ranks.
    Real3View tp("mfsi::fluid::loads::pressureTraction", p.size), tv("mfsi::fluid::loads::viscousTraction", p.size);
    if (p.size > 0) tractionRange(fluid, p.start, p.size, tp, tv);
    const lid_t start = p.start;
    const real x0 = point[0], y0 = point[1], z0 = point[2];
    real r[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    Kokkos::parallel_reduce(
        "mfsi::fluid::loads::patchSum", RangePolicy(ExecSpace(), 0, p.size),
        KOKKOS_LAMBDA(lid_t k, real & a0, real & a1, real & a2, real & a3, real & a4, real & a5, real & a6, real & a7,
                      real & a8, real & a9) {
          const lid_t f = start + k;
          const real A = own(f) < nOwned ? sm(f) : 0.0;
          const real fp[3] = {tp(k, 0) * A, tp(k, 1) * A, tp(k, 2) * A};
          const real fv[3] = {tv(k, 0) * A, tv(k, 1) * A, tv(k, 2) * A};
          const real ft[3] = {fp[0] + fv[0], fp[1] + fv[1], fp[2] + fv[2]};
          const real d[3] = {fc(f, 0) - x0, fc(f, 1) - y0, fc(f, 2) - z0};
          a0 += fp[0];
          a1 += fp[1];
          a2 += fp[2];
          a3 += fv[0];
          a4 += fv[1];
          a5 += fv[2];
          a6 += d[1] * ft[2] - d[2] * ft[1];
          a7 += d[2] * ft[0] - d[0] * ft[2];
          a8 += d[0] * ft[1] - d[1] * ft[0];
          a9 += A;
        },
        r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9]);
    fluid.comm().globalSum(r, 10);
    for (int k = 0; k < 3; ++k) {
      out.pressureForce[k] += r[k];
      out.viscousForce[k] += r[3 + k];
      out.moment[k] += r[6 + k];
    }
    out.area += r[9];
  }
  for (int k = 0; k < 3; ++k) out.force[k] = out.pressureForce[k] + out.viscousForce[k];
  return out;
}

PatchFlow patchFlow(const FluidSolver& fluid, const std::string& patch) {
  const HexMesh& mesh = fluid.mesh();
  const auto& p = mesh.patches()[mesh.patchIndex(patch)];
  ConstRealView sm = fluid.geometry().faceAreaMag, phi = fluid.faceFlux(), pb = fluid.boundaryPressure();
  ConstIndexView own = mesh.faceOwner();
  const lid_t start = p.start, nIn = mesh.nInternalFaces(), nOwned = fluid.ownedCells();
  real r[3] = {0, 0, 0};
  // On a decomposed mesh a ghost cell's patch faces are its owner rank's: counted there.
  Kokkos::parallel_reduce(
      "mfsi::fluid::loads::patchFlow", RangePolicy(ExecSpace(), 0, p.size),
      KOKKOS_LAMBDA(lid_t k, real & q, real & pA, real & A) {
        const lid_t f = start + k;
        if (own(f) >= nOwned) return;
        q += phi(f);
        pA += pb(f - nIn) * sm(f);
        A += sm(f);
      },
      r[0], r[1], r[2]);
  fluid.comm().globalSum(r, 3);
  return {r[0], r[2] > 0 ? r[1] / r[2] : 0, r[2]};
}

real meanPressure(const FluidSolver& fluid) { return meanPressure(fluid, ConstIndexView(), 0); }

real meanPressure(const FluidSolver& fluid, const ConstIndexView& label, int which) {
  ConstRealView V = fluid.geometry().cellVolume, pc = fluid.pressure();
  const ConstIndexView lab = label;
  const bool all = label.extent(0) == 0;
  real r[2] = {0, 0};
  Kokkos::parallel_reduce(
      "mfsi::fluid::loads::meanPressure", RangePolicy(ExecSpace(), 0, fluid.ownedCells()),
      KOKKOS_LAMBDA(lid_t c, real & pV, real & sumV) {
        if (!all && lab(c) != which) return;
        pV += pc(c) * V(c);
        sumV += V(c);
      },
      r[0], r[1]);
  fluid.comm().globalSum(r, 2);
  return r[1] > 0 ? r[0] / r[1] : 0;
}

void baffleNetPressure(const FluidSolver& fluid, const std::string& baffle, const RealView& pNet) {
  const HexMesh& mesh = fluid.mesh();
  const int m = mesh.findPatch(baffle + "_master"), s = mesh.findPatch(baffle + "_slave");
  MFSI_CHECK(m >= 0 && s >= 0, "fluid: baffleNetPressure: no baffle named '" << baffle << "'");
  const auto& pm = mesh.patches()[m];
  const auto& ps = mesh.patches()[s];
  MFSI_CHECK(static_cast<lid_t>(pNet.extent(0)) == pm.size, "fluid: baffleNetPressure: baffle '"
                                                                << baffle << "' has " << pm.size << " faces, view has "
                                                                << pNet.extent(0));
  const lid_t m0 = pm.start - mesh.nInternalFaces(), s0 = ps.start - mesh.nInternalFaces();
  ConstRealView pb = fluid.boundaryPressure();
  Kokkos::parallel_for(
      "mfsi::fluid::loads::baffleNetPressure", RangePolicy(ExecSpace(), 0, pm.size),
      KOKKOS_LAMBDA(lid_t i) { pNet(i) = pb(m0 + i) - pb(s0 + i); });
}

TwoNearest nearestPatchFaces(const FluidSolver& fluid, const std::string& patch, const Vec3& x) {
  const HexMesh& mesh = fluid.mesh();
  const auto& pt = mesh.patches()[mesh.patchIndex(patch)];
  auto fc = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.geometry().faceCentroid);
  auto pb = Kokkos::create_mirror_view_and_copy(HostSpace(), fluid.boundaryPressure());
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  const lid_t nIn = mesh.nInternalFaces();
  TwoNearest near;
  for (lid_t f = pt.start; f < pt.start + pt.size; ++f) {
    if (own(f) >= mesh.nOwnedCells()) continue;  // a ghost's face is its owner's
    const double d = std::sqrt((fc(f, 0) - x[0]) * (fc(f, 0) - x[0]) + (fc(f, 1) - x[1]) * (fc(f, 1) - x[1]) +
                               (fc(f, 2) - x[2]) * (fc(f, 2) - x[2]));
    near.offer(d, pb(f - nIn));
  }
  return near;
}

real boundaryPressureAt(const FluidSolver& fluid, const std::string& patch, const Vec3& x) {
  const HexMesh& mesh = fluid.mesh();
  MFSI_CHECK(mesh.patches()[mesh.patchIndex(patch)].size > 0,
             "fluid: boundaryPressureAt: patch '" << patch << "' has no faces");
  return nearestPatchFaces(fluid, patch, x).blend();
}

}  // namespace mfsi::fluid
