#pragma once
/// \file
/// \brief Rotation-free bending of a quad membrane: a discrete-shell hinge energy on the
/// displacement dofs alone, for sheets whose bending stiffness matters where they go slack
/// (a thin diaphragm that inverts, buckles and wrinkles: the membrane alone has no stiffness
/// there, and its shape is then set by the element size).
///
/// Energy. Each hinge is two triangles sharing an edge x0-x1, with wings x2 (triangle x0 x1 x2)
/// and x3 (triangle x1 x0 x3); theta is the signed angle between their normals, theta0 its value
/// in the reference configuration (a curved reference is stress free), and the hinge stores
/// k (theta - theta0)^2. A quad membrane gets, per interior edge, two hinges: at each end of the
/// edge, the two wings next to that end (one in each quad), with k = D |e|^2 / (4 (A1 + A2)); and
/// per quad the two hinges across its diagonals, each with k = D |d|^2 / (8 A_quad) (A: reference
/// triangle / quad areas). On a square grid these sums give exactly the plate energy
/// D/2 (k11^2 + k22^2 + 2 k12^2) per area for small curvature (the nu = 0 form of the Kirchhoff
/// plate: the edge hinges see k11 and k22, the diagonal hinges the twist k12): derived in the .cpp
/// and checked on a cylinder, a saddle and a sphere by the tests. D = E h^3 / (12 (1 - nu^2)).
/// Free and clamped rims carry no hinge: the rim is simply supported in bending.
///
/// The hinges are assembly items of four nodes after the elements, bars and springs, so the CSR
/// pattern couples a hinge's far nodes. Their tangent is the Gauss-Newton part 2 k g g^T (g the
/// angle's gradient): positive semi-definite, so CG applies; the neglected 2 k (theta - theta0)
/// d2theta/dx2 makes Newton linear where a fold carries a large angle change, which the time step's
/// line search absorbs.
#include "kernels/CsrAssembly.hpp"
#include "structure/membrane/MembraneMesh.hpp"

#include <array>
#include <vector>

namespace mfsi {

/// \brief Hinges of a membrane in device form (plus their nodes on the host, for the assembly map).
struct MembraneHinges {
  Kokkos::View<lid_t* [4], MemSpace> nodes;  ///< x0, x1 (the edge), x2, x3 (the wings)
  RealView stiffness;                       ///< k [N m]
  RealView restAngle;                       ///< theta0 [rad]
  std::vector<std::array<lid_t, kMaxItemNodes>> hostNodes;
  lid_t size() const { return static_cast<lid_t>(stiffness.extent(0)); }
};

/// \brief The hinges of a quad membrane with bending stiffness D [N m]. Throws InputError when the
/// mesh has triangles (their hinge constants are not calibrated) or D is not positive.
MembraneHinges buildMembraneHinges(const MembraneMesh& mesh, real bendingStiffness);

/// \brief Residual slots (R = -dE/du; external zero) of the hinges, written to item rows
/// firstItem + h, for displacement u (3 per node).
void membraneHingeResidualItems(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                                const ConstRealView& u, lid_t firstItem, const ItemValuesView& residual,
                                const ItemValuesView& external);

/// \brief Tangent slots 2 k g g^T of the hinges (rows firstItem + h), or, with `rowSums`, their
/// absolute row sums (the lumped solver's stiffness).
void membraneHingeTangentItems(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                               const ConstRealView& u, lid_t firstItem, bool rowSums, const ItemValuesView& out);

/// \brief The bending energy sum k (theta - theta0)^2 at displacement u [J].
real membraneBendingEnergy(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                           const ConstRealView& u);

namespace membrane {

/// \brief Signed angle theta of a hinge (see the file comment) and its gradient with respect to
/// the four points. Returns false (theta = 0, gradient zero) for a degenerate triangle.
KOKKOS_INLINE_FUNCTION bool hingeAngle(const real x[4][3], real& theta, real grad[4][3]) {
  real e[3], a2[3], a3[3];
  for (int k = 0; k < 3; ++k) {
    e[k] = x[1][k] - x[0][k];
    a2[k] = x[2][k] - x[0][k];
    a3[k] = x[3][k] - x[0][k];
  }
  const real n1[3] = {e[1] * a2[2] - e[2] * a2[1], e[2] * a2[0] - e[0] * a2[2], e[0] * a2[1] - e[1] * a2[0]};
  const real n2[3] = {a3[1] * e[2] - a3[2] * e[1], a3[2] * e[0] - a3[0] * e[2], a3[0] * e[1] - a3[1] * e[0]};
  const real le2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
  const real l1 = kmath::sqrt(n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]);
  const real l2 = kmath::sqrt(n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]);
  theta = 0;
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k) grad[a][k] = 0;
  if (!(le2 > 0) || !(l1 > 1e-12 * le2) || !(l2 > 1e-12 * le2)) return false;
  const real le = kmath::sqrt(le2);
  real m1[3], m2[3];
  for (int k = 0; k < 3; ++k) {
    m1[k] = n1[k] / l1;
    m2[k] = n2[k] / l2;
  }
  const real c = m1[0] * m2[0] + m1[1] * m2[1] + m1[2] * m2[2];
  const real s = ((m1[1] * m2[2] - m1[2] * m2[1]) * e[0] + (m1[2] * m2[0] - m1[0] * m2[2]) * e[1] +
                  (m1[0] * m2[1] - m1[1] * m2[0]) * e[2]) /
                 le;
  theta = kmath::atan2(s, c);
  // A wing moves the angle along its triangle's normal, by 1 / (its height over the edge); the
  // edge's ends take the rest so that translations and rotations leave theta unchanged.
  const real h1 = l1 / le, h2 = l2 / le;
  const real t2 = (a2[0] * e[0] + a2[1] * e[1] + a2[2] * e[2]) / le2;
  const real t3 = (a3[0] * e[0] + a3[1] * e[1] + a3[2] * e[2]) / le2;
  for (int k = 0; k < 3; ++k) {
    grad[2][k] = -m1[k] / h1;
    grad[3][k] = -m2[k] / h2;
    grad[0][k] = -(1 - t2) * grad[2][k] - (1 - t3) * grad[3][k];
    grad[1][k] = -t2 * grad[2][k] - t3 * grad[3][k];
  }
  return true;
}

/// theta - theta0 wrapped into (-pi, pi].
KOKKOS_INLINE_FUNCTION real hingeAngleChange(real theta, real theta0) {
  constexpr real pi = 3.14159265358979323846;
  real d = theta - theta0;
  if (d > pi) d -= 2 * pi;
  if (d <= -pi) d += 2 * pi;
  return d;
}

}  // namespace membrane
}  // namespace mfsi
