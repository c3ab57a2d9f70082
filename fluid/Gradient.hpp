#pragma once
/// \file
/// \brief Cell gradients of scalar and vector fields (Green-Gauss linear or least squares).
#include "core/MeshGeometry.hpp"
#include "fluid/FluidOptions.hpp"
#include "fluid/FvFaceData.hpp"

namespace mfsi::fluid {

/// Gradient of a vector field: `G(c, i, j) = d u_j / d x_i`.
using Tensor3View = Kokkos::View<real* [3][3], MemSpace>;
using ConstTensor3View = Kokkos::View<const real* [3][3], MemSpace, RandomRead>;

/// \brief Gradient of the cell field `phi` with boundary-face values `phiB` (size nBoundaryFaces,
/// index f - nInternalFaces) into `grad` (per cell). Gauss: (1/V) sum_f phi_f S_f with linear
/// interpolation; least squares: inverse-square-distance weights over face neighbours and boundary
/// faces. Each cell gathers its own faces (deterministic, no atomics). A non-empty `cells` limits
/// the update to the listed cells (the others keep their values).
void cellGradient(const ExecSpace& exec, GradientScheme scheme, const HexMesh& mesh, const MeshGeometry& geo,
                  const FvFaceData& fd, const ConstRealView& phi, const ConstRealView& phiB, const Real3View& grad,
                  const ConstIndexView& cells = {});

/// \brief Gradient of a vector field, `G(c, i, j) = d u_j / d x_i`; `uB` holds boundary-face values.
void cellGradient(const ExecSpace& exec, GradientScheme scheme, const HexMesh& mesh, const MeshGeometry& geo,
                  const FvFaceData& fd, const ConstReal3View& u, const ConstReal3View& uB, const Tensor3View& grad,
                  const ConstIndexView& cells = {});

/// \brief The cells that own at least one boundary face, in increasing order: the only cells whose
/// gradient depends on boundary values.
IndexView boundaryCells(const HexMesh& mesh);

}  // namespace mfsi::fluid
