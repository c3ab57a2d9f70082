#pragma once
/// \file
/// \brief Finite-volume assembly kernels of a cell-centred operator on a `HexMesh`: the CSR sparsity
/// (built once per topology), the refill of matrix values from per-face coefficients, and the
/// face-to-cell divergence of per-face fluxes.
///
/// Why two reduction modes: every face contributes to two cells. The default (`Gather`) writes one
/// value per face and lets each cell sum its own faces through the mesh's cell -> faces CSR: no
/// atomics, and the summation order is fixed, so results are bitwise reproducible run to run.
/// `Scatter` adds each face's value to its two cells with `Kokkos::ScatterView` (atomics on the
/// device, duplicated arrays on threads); it exists for the performance comparison in perf/.
#include "core/HexMesh.hpp"
#include "kernels/CsrMatrix.hpp"

#include <Kokkos_ScatterView.hpp>

#include <string>
#include <type_traits>

namespace mfsi::fluid {

/// \brief How face contributions are reduced onto cells.
enum class ReductionMode {
  Gather,   ///< per-face values, then a per-cell sum over the cell's faces (deterministic, default)
  Scatter,  ///< per-face kernel adding into both cells through Kokkos::ScatterView
};

const char* toString(ReductionMode mode);

/// \brief Sparsity of a cell-centred operator: one row per cell, one entry per face neighbour plus
/// the diagonal, and the maps that let face kernels find their matrix entries.
struct FvSparsity {
  lid_t nRows = 0;
  IndexView rowPtr;        ///< size nRows + 1
  IndexView colIdx;        ///< sorted per row
  IndexView diagIdx;       ///< position of the diagonal of each row
  IndexView cellFacePos;   ///< per entry of mesh.cellFaces(): position of that face's off-diagonal in the
                           ///< cell's row, -1 for boundary faces
  IndexView ownerPos;      ///< per internal face: position of (owner, neighbour)
  IndexView neighbourPos;  ///< per internal face: position of (neighbour, owner)
  CsrRowRuns runs;         ///< row runs of the sparsity (kernels/CsrMatrix.hpp)
};

/// \brief Build the sparsity of `mesh` (host-side build, copied to the device; once per topology).
FvSparsity buildSparsity(const HexMesh& mesh);

/// \brief A CSR matrix that shares the pattern of `s` and owns fresh values (label `label`).
CsrMatrix makeMatrix(const FvSparsity& s, const std::string& label);

/// \brief Per-face matrix contributions of a face-based operator.
///
/// For internal face f with owner P and neighbour N, the owner's row gets `ownerDiag(f)` on its
/// diagonal and `upper(f)` in column N; the neighbour's row gets `neighbourDiag(f)` on its diagonal
/// and `lower(f)` in column P. Boundary faces only use `ownerDiag`.
struct FaceCoefficients {
  RealView ownerDiag;      ///< size nFaces
  RealView neighbourDiag;  ///< size nFaces (internal part used)
  RealView upper;          ///< size nFaces (internal part used)
  RealView lower;          ///< size nFaces (internal part used)
};

/// \brief Allocate face coefficients for `mesh`, labelled `<prefix>::ownerDiag` etc.
FaceCoefficients allocateFaceCoefficients(const HexMesh& mesh, const std::string& prefix);

/// \brief Refill `A.values` (pattern of `s`) from face coefficients plus a per-cell diagonal term.
void assembleMatrix(const ExecSpace& exec, const HexMesh& mesh, const FvSparsity& s, const FaceCoefficients& fc,
                    const ConstRealView& cellDiag, const CsrMatrix& A, ReductionMode mode);

namespace detail {
template <class V>
KOKKOS_INLINE_FUNCTION std::enable_if_t<static_cast<int>(V::rank) == 1, typename V::reference_type> comp(const V& v,
                                                                                                         lid_t i, int) {
  return v(i);
}
template <class V>
KOKKOS_INLINE_FUNCTION std::enable_if_t<static_cast<int>(V::rank) == 2, typename V::reference_type> comp(const V& v,
                                                                                                         lid_t i,
                                                                                                         int k) {
  return v(i, k);
}
}  // namespace detail

/// \brief Face-to-cell divergence: `out(c, k) = sign * sum_{f in c} flux(f, k)` where a face counts
/// +1 for its owner and -1 for its neighbour (fluxes are "out of the owner").
///
/// `FluxView` / `OutView` are rank-1 (one component) or rank-2 (`NC` components) device Views.
/// With `accumulate` the result is added to `out` instead of overwriting it.
template <int NC, class FluxView, class OutView>
void divergence(const ExecSpace& exec, const HexMesh& mesh, const FluxView& flux, const OutView& out,
                ReductionMode mode, bool accumulate = false, real sign = 1.0) {
  using detail::comp;
  const lid_t nCells = mesh.nCells();
  if (mode == ReductionMode::Gather) {
    ConstIndexView off = mesh.cellFaceOffsets();
    ConstIndexView cf = mesh.cellFaces();
    ConstIndexView own = mesh.faceOwner();
    Kokkos::parallel_for(
        "mfsi::fluid::fv::divergence::gather", RangePolicy(exec, 0, nCells), KOKKOS_LAMBDA(lid_t c) {
          real sum[NC];
          for (int k = 0; k < NC; ++k) sum[k] = 0.0;
          for (lid_t e = off(c); e < off(c + 1); ++e) {
            const lid_t f = cf(e);
            const real s = own(f) == c ? 1.0 : -1.0;
            for (int k = 0; k < NC; ++k) sum[k] += s * comp(flux, f, k);
          }
          for (int k = 0; k < NC; ++k) {
            if (accumulate)
              comp(out, c, k) += sign * sum[k];
            else
              comp(out, c, k) = sign * sum[k];
          }
        });
  } else {
    if (!accumulate) {
      Kokkos::parallel_for(
          "mfsi::fluid::fv::divergence::zero", RangePolicy(exec, 0, nCells), KOKKOS_LAMBDA(lid_t c) {
            for (int k = 0; k < NC; ++k) comp(out, c, k) = 0.0;
          });
    }
    auto sv = Kokkos::Experimental::create_scatter_view(out);
    ConstIndexView own = mesh.faceOwner();
    ConstIndexView nei = mesh.faceNeighbour();
    Kokkos::parallel_for(
        "mfsi::fluid::fv::divergence::scatter", RangePolicy(exec, 0, mesh.nFaces()), KOKKOS_LAMBDA(lid_t f) {
          auto acc = sv.access();
          const lid_t o = own(f), n = nei(f);
          for (int k = 0; k < NC; ++k) {
            const real v = sign * comp(flux, f, k);
            if constexpr (static_cast<int>(OutView::rank) == 1) {
              acc(o) += v;
              if (n >= 0) acc(n) += -v;
            } else {
              acc(o, k) += v;
              if (n >= 0) acc(n, k) += -v;
            }
          }
        });
    OutView target = out;
    Kokkos::Experimental::contribute(target, sv);
  }
}

}  // namespace mfsi::fluid
