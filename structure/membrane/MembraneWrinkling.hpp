#pragma once
/// \file
/// \brief Tension-field wrinkling model (mixed stress-strain criterion, Roddeman et al. 1987;
/// Kang & Im 1997) and the per-Gauss-point constitutive law of the membrane kernels.
///
/// A membrane cannot carry compression: it wrinkles. Per material point, with the elastic trial
/// stress S = C E (principal s1 >= s2) and the principal strains e1 >= e2:
///  - taut     if s2 > 0:           S = C E, tangent C;
///  - slack    if e1 <= 0:          S = 0;
///  - wrinkled otherwise:           uniaxial tension along the major principal strain direction n,
///                                  S = E e1 n (x) n (the uniaxial law of an isotropic sheet whose
///                                  transverse strain is free: e2 includes the wrinkling strain).
/// The stress is continuous across the state boundaries (at s2 = 0 the elastic stress is exactly
/// uniaxial with s1 = E e1; at e1 = 0 it vanishes).
///
/// Tangent. In the wrinkled state the exact derivative of S = E e1 n(x)n is
///   dS = E (n.dE.n) n(x)n + E e1/(e1 - e2) (m.dE.n) (n(x)m + m(x)n),
/// the second term from the rotation of n (m is the minor direction); e1 - e2 > (1 + nu) e1 > 0
/// there, so it is bounded. It has no stiffness for stretching along m, and the slack state none
/// at all, which makes the Newton matrix singular; the safeguard adds `eta E (m(x)m)(x)(m(x)m)`
/// (wrinkled) or `eta C` (slack) to the tangent only. The stress, hence the converged answer, is
/// unchanged; Newton stays quadratic in taut regions and nearly so elsewhere.
#include "structure/membrane/MembraneMaterial.hpp"

namespace mfsi::membrane {

/// \brief Tension-field stress S and tangent Ct for the total strain e (Voigt). Returns the state.
KOKKOS_INLINE_FUNCTION MembraneWrinkleState tensionField(real E, real nu, real eta, const real e[3], real S[3],
                                                         real Ct[3][3]) {
  real C[3][3];
  planeStressMatrix(E, nu, C);
  for (int i = 0; i < 3; ++i) S[i] = C[i][0] * e[0] + C[i][1] * e[1] + C[i][2] * e[2];
  real s1, s2;
  principal2(S, s1, s2);
  if (s2 > 0) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Ct[i][j] = C[i][j];
    return MembraneWrinkleState::Taut;
  }
  // Principal strains of {e11, e22, 2 e12}.
  const real mean = 0.5 * (e[0] + e[1]);
  const real d = 0.5 * (e[0] - e[1]);
  const real g = 0.5 * e[2];
  const real R = kmath::sqrt(d * d + g * g);
  const real e1 = mean + R;  // e2 = mean - R, so e1 - e2 = 2 R
  if (e1 <= 0 || R <= 0) {
    // R = 0 with s2 <= 0 means isotropic non-positive strain: slack as well.
    for (int i = 0; i < 3; ++i) {
      S[i] = 0;
      for (int j = 0; j < 3; ++j) Ct[i][j] = eta * C[i][j];
    }
    return MembraneWrinkleState::Slack;
  }
  // Major direction n = (cos t, sin t) with tan 2t = 2 e12 / (e11 - e22); minor m = (-sin t, cos t).
  const real c2 = d / R, sn2 = g / R;  // cos 2t, sin 2t
  const real cc = 0.5 * (1 + c2), ss = 0.5 * (1 - c2), cs = 0.5 * sn2;  // cos^2, sin^2, cos sin
  const real a[3] = {cc, ss, cs};            // n(x)n in stress Voigt; also d e1 / d{E11, E22, 2E12}
  const real b[3] = {-cs, cs, 0.5 * c2};     // m.dE.n per {dE11, dE22, d(2E12)}
  const real c[3] = {ss, cc, -cs};           // m(x)m
  const real shear = 2 * E * e1 / (2 * R);   // 2 E e1 / (e1 - e2)
  for (int i = 0; i < 3; ++i) {
    S[i] = E * e1 * a[i];
    for (int j = 0; j < 3; ++j) Ct[i][j] = E * a[i] * a[j] + shear * b[i] * b[j] + eta * E * c[i] * c[j];
  }
  return MembraneWrinkleState::Wrinkled;
}

/// \brief Per-point membrane law used by the kernels: membrane force N = h S (N/m) including the
/// pre-stress, and its tangent h Ct.
///
/// The pre-stress T0 enters as the equivalent isotropic pre-strain e0 = T0 (1 - nu) / (E h): for a
/// taut point h C (E + e0 I) = h C E + T0 I exactly as specified, and the wrinkling criterion then
/// acts on the total membrane force (a pre-tensioned sheet wrinkles when the applied compression
/// exceeds the pre-tension, not at the first compressive increment).
struct MembraneLaw {
  real E = 0, nu = 0, h = 0;
  real preStrain = 0;
  real eta = 1e-3;
  /// Fraction f of the elastic law a wrinkled or slack point keeps: N = (1 - f) N_tf + f h C E
  /// (continuous at both state boundaries, since N_tf = h C E where taut). 0: the pure tension
  /// field. A slack sheet otherwise has no in-plane stiffness at all, so its nodes drift in its plane.
  real residual = 0;
  bool wrinkling = false;  ///< tension-field model on

  KOKKOS_INLINE_FUNCTION MembraneWrinkleState evaluate(const real strain[3], real N[3], real Ct[3][3]) const {
    const real e[3] = {strain[0] + preStrain, strain[1] + preStrain, strain[2]};
    MembraneWrinkleState state = MembraneWrinkleState::Taut;
    if (wrinkling) {
      state = membrane::tensionField(E, nu, eta, e, N, Ct);
      if (residual > 0 && state != MembraneWrinkleState::Taut) {
        real C[3][3];
        planeStressMatrix(E, nu, C);
        for (int i = 0; i < 3; ++i) {
          N[i] = (1 - residual) * N[i] + residual * (C[i][0] * e[0] + C[i][1] * e[1] + C[i][2] * e[2]);
          for (int j = 0; j < 3; ++j) Ct[i][j] = (1 - residual) * Ct[i][j] + residual * C[i][j];
        }
      }
    } else {
      planeStressMatrix(E, nu, Ct);
      for (int i = 0; i < 3; ++i) N[i] = Ct[i][0] * e[0] + Ct[i][1] * e[1] + Ct[i][2] * e[2];
    }
    for (int i = 0; i < 3; ++i) {
      N[i] *= h;
      for (int j = 0; j < 3; ++j) Ct[i][j] *= h;
    }
    return state;
  }
};

}  // namespace mfsi::membrane
