#pragma once
/// \file
/// \brief Membrane material: St. Venant-Kirchhoff in plane stress (Green-Lagrange strain E,
/// second Piola-Kirchhoff stress S = C : E), thickness, density and an isotropic in-plane
/// pre-stress, plus the device-side constitutive law used by the element kernels.
///
/// Voigt convention everywhere in the membrane code: strain {E11, E22, 2 E12} (engineering
/// shear), stress {S11, S22, S12}, in a local orthonormal basis of the reference tangent plane.
#include "core/Types.hpp"

namespace mfsi {

/// \brief Material data of one membrane.
struct MembraneMaterial {
  real youngsModulus = 0;   ///< E (Pa)
  real poissonRatio = 0.3;  ///< nu, in [0, 0.5] (plane stress does not lock at 0.5)
  real thickness = 0;       ///< h (m)
  real density = 0;         ///< rho (kg/m^3); needed for dynamics only
  real preStress = 0;       ///< T0 (N/m): isotropic membrane force added to h S in the reference state
  /// Plate bending on top of the membrane (MembraneBending.hpp), D = E h^3 / (12 (1 - nu^2)).
  bool bending = false;
};

/// The plate bending stiffness D = E h^3 / (12 (1 - nu^2)) [N m] of the material.
inline real plateBendingStiffness(const MembraneMaterial& m) {
  return m.youngsModulus * m.thickness * m.thickness * m.thickness / (12 * (1 - m.poissonRatio * m.poissonRatio));
}

/// \brief Throws InputError for E <= 0, h <= 0, nu outside [0, 0.5], rho < 0.
void validate(const MembraneMaterial& material);

/// Wrinkling model of the constitutive law.
enum class MembraneWrinklingModel {
  None,          ///< plain St. Venant-Kirchhoff; compressive stresses allowed
  TensionField,  ///< principal stresses never negative: taut / wrinkled / slack (MembraneWrinkling.hpp)
};

/// State of a material point under the tension-field model (None: always Taut).
enum class MembraneWrinkleState : int { Taut = 0, Wrinkled = 1, Slack = 2 };

const char* toString(MembraneWrinklingModel model);
const char* toString(MembraneWrinkleState state);

namespace membrane {

/// \brief Plane-stress St. Venant-Kirchhoff matrix C (Voigt, engineering shear).
KOKKOS_INLINE_FUNCTION void planeStressMatrix(real E, real nu, real C[3][3]) {
  const real f = E / (1 - nu * nu);
  C[0][0] = f;
  C[0][1] = f * nu;
  C[0][2] = 0;
  C[1][0] = f * nu;
  C[1][1] = f;
  C[1][2] = 0;
  C[2][0] = 0;
  C[2][1] = 0;
  C[2][2] = f * (1 - nu) / 2;
}

/// \brief Principal values s1 >= s2 of a symmetric 2x2 tensor given in Voigt stress form
/// {a11, a22, a12}.
KOKKOS_INLINE_FUNCTION void principal2(const real a[3], real& s1, real& s2) {
  const real m = 0.5 * (a[0] + a[1]);
  const real d = 0.5 * (a[0] - a[1]);
  const real r = kmath::sqrt(d * d + a[2] * a[2]);
  s1 = m + r;
  s2 = m - r;
}

}  // namespace membrane
}  // namespace mfsi
