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

/// \brief Green-Gauss linear gradient as a per-cell stencil laid out in the order of
/// `mesh.cellFaces()`: grad(c) = self(c) phi_c + sum_e coef(e) phi_other(e), with the face weights,
/// signed face areas and 1/V folded in. The stencil is read contiguously, where the face-based
/// formula reads face data scattered (faces of a cell are far apart in face order): same values
/// to round-off, about twice as fast. Rebuild it whenever the geometry changes.
struct GradientStencil {
  Real3View self;   ///< per cell
  IndexView other;  ///< per cell-face entry: neighbour cell, or -(b + 1) for boundary face b
  Real3View coef;   ///< per cell-face entry
};

/// \brief Allocate a stencil for `mesh` (labels `mfsi::fluid::gradientStencil::*`).
GradientStencil allocateGradientStencil(const HexMesh& mesh);

/// \brief Fill `st` from the current geometry and face weights (same formula as
/// `GradientScheme::GaussLinear`).
void computeGradientStencil(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo, const FvFaceData& fd,
                            const GradientStencil& st);

/// \brief Gauss-linear gradient of a scalar through the stencil; `cells` as in cellGradient.
void cellGradient(const ExecSpace& exec, const HexMesh& mesh, const GradientStencil& st, const ConstRealView& phi,
                  const ConstRealView& phiB, const Real3View& grad, const ConstIndexView& cells = {});

/// \brief Gauss-linear gradient of a vector field through the stencil.
void cellGradient(const ExecSpace& exec, const HexMesh& mesh, const GradientStencil& st, const ConstReal3View& u,
                  const ConstReal3View& uB, const Tensor3View& grad, const ConstIndexView& cells = {});

/// \brief The cells that own at least one boundary face, in increasing order: the only cells whose
/// gradient depends on boundary values.
IndexView boundaryCells(const HexMesh& mesh);

}  // namespace mfsi::fluid
