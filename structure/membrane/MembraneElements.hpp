#pragma once
/// \file
/// \brief Element kernels of the Total-Lagrangian membrane: per element (and per bar / spring)
/// internal and pressure forces, tangent matrices, lumped stiffness, mass, and element-centre
/// strain/stress output. Every kernel writes one slot per item; `gatherItemVectors` /
/// `gatherItemMatrices` (kernels/CsrAssembly.hpp) then sum them per node without atomics.
///
/// Kinematics. At each Gauss point an orthonormal basis (e1, e2) of the reference tangent plane
/// (n from the reference tangents X,xi x X,eta; e1 the projection of the global x axis, or of y
/// when x is nearly normal; e2 = n x e1) gives local coordinates s. With g_a = dx/ds_a the
/// current tangents, the Green-Lagrange strain is E_ab = (g_a . g_b - delta_ab) / 2 (exact for
/// any rotation and stretch). With the membrane force N = h S, the internal force of node A is
/// f_A = int N_ab dN_A/ds_b g_a dA0, and the tangent is
///   K_AB = int B_A^T (h C_t) B_B dA0  +  int (dN_A/ds_a N_ab dN_B/ds_b) dA0 I,
/// B_A the rows {dN_A,1 g_1; dN_A,2 g_2; dN_A,1 g_2 + dN_A,2 g_1}. Quads use 2 x 2 Gauss points
/// (exact for the pressure terms), triangles one (constant strain).
#include "structure/membrane/MembraneMesh.hpp"
#include "structure/membrane/MembraneOptions.hpp"
#include "structure/membrane/MembraneWrinkling.hpp"

namespace mfsi {

/// Item vector width (4 nodes x 3 dofs) and matrix size.
inline constexpr int kMembraneItemDofs = 12;
inline constexpr int kMembraneItemMatrix = kMembraneItemDofs * kMembraneItemDofs;

/// \brief Reference geometry per element and Gauss point, computed once.
struct MembraneReferenceGeometry {
  Kokkos::View<real* [4][4][2], MemSpace> dNds;  ///< (element, gauss point, node, local direction)
  Kokkos::View<real* [4], MemSpace> weight;      ///< Gauss weight x area Jacobian (0 for unused points)
};

/// \brief Compute the reference geometry of every element of `mesh`.
MembraneReferenceGeometry computeMembraneReferenceGeometry(const ExecSpace& exec, const MembraneMesh& mesh);

/// \brief Everything an element kernel reads besides the displacement.
struct MembraneElementData {
  ConstQuad4View elements;
  ConstReal3View X;  ///< reference positions
  Kokkos::View<const real* [4][4][2], MemSpace> dNds;
  Kokkos::View<const real* [4], MemSpace> weight;
  membrane::MembraneLaw law;
  real tangentFloor = 0;  ///< N (N/m): geometric-stiffness floor of the smallest principal force
  real density = 0;       ///< rho h (kg/m^2)
};

/// \brief Build the kernel data from a mesh, its geometry and the options.
MembraneElementData makeMembraneElementData(const MembraneMesh& mesh, const MembraneReferenceGeometry& geometry,
                                            const MembraneOptions& options);

/// \brief Pressure handling inside the element kernels.
struct MembranePressureKernel {
  ConstRealView nodePressure;     ///< size nNodes: effective nodal pressure (Pa)
  ConstRealView elementPressure;  ///< size nElements or 0
  bool follower = true;
  bool lumped = false;
  bool stiffness = true;  ///< tangent kernel: add the symmetrised follower load stiffness
};

/// \brief Axial bars and node springs in device form (items after the elements).
struct MembraneLineItems {
  Kokkos::View<lid_t* [2], MemSpace> barNodes;
  RealView barEA, barLength;  ///< EA and reference length
  Kokkos::View<int*, MemSpace> barTensionOnly;
  IndexView springNode;
  Real3View springAnchor;
  RealView springStiffness, springRestLength;
  lid_t nBars() const { return static_cast<lid_t>(barEA.extent(0)); }
  lid_t nSprings() const { return static_cast<lid_t>(springStiffness.extent(0)); }
};

/// \brief Residual slots R_e = f_ext - f_int and external-force slots of elements (rows 0..nE-1)
/// and line items (rows nE.., internal forces only), for displacement u (flat, 3 per node).
void membraneResidualItems(const ExecSpace& exec, const MembraneElementData& data,
                           const MembranePressureKernel& pressure, const MembraneLineItems& lines,
                           const ConstRealView& u, const ItemValuesView& residual, const ItemValuesView& external);

/// \brief Tangent slots K_e = d f_int / du - d f_ext / du of elements and line items.
void membraneTangentItems(const ExecSpace& exec, const MembraneElementData& data,
                          const MembranePressureKernel& pressure, const MembraneLineItems& lines,
                          const ConstRealView& u, const ItemValuesView& tangent);

/// \brief Lumped stiffness slots: absolute row sums of the material + geometric tangent.
void membraneLumpedStiffnessItems(const ExecSpace& exec, const MembraneElementData& data,
                                  const MembraneLineItems& lines, const ConstRealView& u,
                                  const ItemValuesView& rowSums);

/// \brief Mass slots of elements: consistent 12 x 12 matrices (rho h int N_A N_B dA0 I), or
/// lumped row sums (12 per element). Line items get zero mass.
void membraneMassItems(const ExecSpace& exec, const MembraneElementData& data, lid_t nItems, bool lumped,
                       const ItemValuesView& mass);

/// \brief The volume the surface sweeps from its reference to its deformed position, returned:
/// the sum over elements of the exact volume of the trilinear hex between the reference and the
/// current quad (a triangle as a quad with its last node repeated), positive along the element
/// normals. It is what a matching fluid mesh's swept-volume fluxes add up to (fluid/MeshFlux), also
/// where the surface's free edges slide in planes (a one-cell-thick 2D mesh), and it is additive
/// over successive moves. Into the gradient slots (elements' rows; line items' rows zero) goes
/// int N_A n da over the current element, the consistent nodal load of a unit follower pressure:
/// the volume's gradient in every direction a clamped rim or a motion plane leaves free.
real membraneVolumeItems(const ExecSpace& exec, const MembraneElementData& data, lid_t nItems,
                         const ConstRealView& u, const ItemValuesView& gradient);

/// \brief Element-centre results: Green-Lagrange strain {E11, E22, 2 E12} and PK2 stress
/// {S11, S22, S12} (Pa, including the pre-stress T0/h, after wrinkling) in the local basis,
/// principal stresses s1 >= s2, von Mises, wrinkle state (MembraneWrinkleState as int), and the
/// local basis vector e1 in global components (e2 = n x e1). For a flat mesh in the xy plane the
/// basis is the global x, y.
struct MembraneElementOutput {
  Kokkos::View<real* [3], MemSpace> strain;
  Kokkos::View<real* [3], MemSpace> stress;
  RealView principal1, principal2, vonMises;
  Kokkos::View<int*, MemSpace> wrinkleState;
  /// Wrinkle state at each Gauss point (quads: the 2 x 2 points in the order (-,-), (+,-), (-,+),
  /// (+,+); triangles: the centroid in slot 0 and -1 in the others).
  Kokkos::View<int* [4], MemSpace> gaussWrinkleState;
  Real3View basis1;
};

MembraneElementOutput allocateMembraneElementOutput(lid_t nElements);

void membraneElementOutput(const ExecSpace& exec, const MembraneElementData& data, const ConstRealView& u,
                           const MembraneElementOutput& out);

}  // namespace mfsi
