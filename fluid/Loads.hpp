#pragma once
/// \file
/// \brief Fluid loads on boundaries: traction per face, force and moment per patch, and the net
/// pressure across a baffle (the load on a membrane).
#include "fluid/FluidSolver.hpp"

#include <string>

namespace mfsi::fluid {

/// \brief Integrated loads on a patch (force exerted by the fluid on the boundary).
struct PatchLoads {
  Vec3 pressureForce{0, 0, 0};  ///< sum_f p_f S_f
  Vec3 viscousForce{0, 0, 0};   ///< sum_f -(tau . S)_f
  Vec3 force{0, 0, 0};          ///< total
  Vec3 moment{0, 0, 0};         ///< sum_f (x_f - point) x force_f
  real area = 0;
};

/// \brief Traction (force per unit area exerted by the fluid on the boundary) on each face of
/// patch `patch`, split in its pressure part p n and viscous part -tau.n, with n the unit normal
/// out of the fluid and tau = mu (grad u + grad u^T). Views have the patch's size.
///
/// The normal derivative of u uses the boundary value and the owner cell, (u_b - u_P) / d_n; the
/// transposed part uses the owner's cell gradient from the last outer iteration.
void boundaryTraction(const FluidSolver& fluid, const std::string& patch, const Real3View& pressureTraction,
                      const Real3View& viscousTraction);

/// \brief Force and moment about `point` on a patch, or on both sides of a baffle when `name` is
/// a baffle name (the two sides' pressure parts then give the net load on the membrane).
PatchLoads patchLoads(const FluidSolver& fluid, const std::string& name, const Vec3& point = {0, 0, 0});

/// \brief Flow through a patch: the volumetric flow rate out of the fluid, sum_f u_f . S_f
/// (absolute velocity; the mesh flux is not subtracted, so a moving patch counts the fluid it
/// carries), and the area-weighted mean of the boundary pressure.
struct PatchFlow {
  real flowRate = 0;      ///< [m^3/s], positive out of the fluid
  real meanPressure = 0;  ///< [Pa]
  real area = 0;          ///< [m^2]
};
PatchFlow patchFlow(const FluidSolver& fluid, const std::string& patch);

/// \brief Volume-weighted mean of the cell pressure over the fluid [Pa].
real meanPressure(const FluidSolver& fluid);
/// \brief The same over the cells c with label(c) == which (every cell when `label` is empty): one
/// fluid (FluidSolver::cellFluidIndex: -1 the options' own, i FluidOptions::regions[i]) or one
/// closed region (FluidSolver::cellClosedRegion).
real meanPressure(const FluidSolver& fluid, const ConstIndexView& label, int which);

/// \brief Net pressure across a baffle per face pair: pNet(i) = p(master face i) - p(slave face i)
/// [Pa]. The master's outward normal is the baffle normal, so the pressure load on the membrane is
/// pNet times the baffle normal (pointing from the master side to the slave side).
void baffleNetPressure(const FluidSolver& fluid, const std::string& baffle, const RealView& pNet);

/// \brief The two nearest of a stream of (distance, value) candidates (the first one offered wins
/// a tie), and their inverse-distance blend: what boundaryPressureAt takes from a patch's faces.
struct TwoNearest {
  double d1 = 1e300, v1 = 0, d2 = 1e300, v2 = 0;
  void offer(double d, double v) {
    if (d < d1) {
      d2 = d1;
      v2 = v1;
      d1 = d;
      v1 = v;
    } else if (d < d2) {
      d2 = d;
      v2 = v;
    }
  }
  bool empty() const { return !(d1 < 1e300); }
  /// The blend (the nearest value alone when there is one candidate or it sits at the point).
  double blend() const { return (!(d2 < 1e300) || d1 < 1e-12) ? v1 : (v1 / d1 + v2 / d2) / (1 / d1 + 1 / d2); }
};

/// \brief The two faces of `patch` nearest to x (by centroid) among this rank's owned cells' faces,
/// with their boundary pressures: on one process, among all of them.
TwoNearest nearestPatchFaces(const FluidSolver& fluid, const std::string& patch, const Vec3& x);

/// \brief Pressure at point `x` on patch `patch`: the boundary values of the two faces whose
/// centroids are nearest, blended by inverse distance (the value of a face whose centroid is at `x`).
real boundaryPressureAt(const FluidSolver& fluid, const std::string& patch, const Vec3& x);

}  // namespace mfsi::fluid
