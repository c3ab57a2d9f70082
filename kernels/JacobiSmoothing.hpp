#pragma once
/// \file
/// \brief Jacobi point-Laplacian smoothing of a nodal vector field over a node -> node graph: the
/// kernel of the mesh motion (coupling/motion), which smooths the displacement of the interior
/// nodes from the reference mesh while boundary nodes keep their prescribed values.
#include "core/Types.hpp"

#include <cstdint>

namespace mfsi {

/// \brief The graph a sweep walks. `offsets`/`neighbours`: CSR node -> node adjacency (e.g.
/// HexMesh::nodeNodeOffsets / nodeNodes, the cell edges). `fixed(i) != 0`: node i keeps its
/// value. `weights` (optional, one per adjacency entry): the weighted mean sum_j w_ij d_j / sum_j
/// w_ij; empty: the plain mean over the neighbours. `slideNormal` (optional, one per node): a
/// free node with a nonzero unit normal n moves in its tangent plane only (a mesh node sliding along
/// a flat wall): its update is projected, v - (v.n) n, and its normal component keeps its value.
struct SmoothingGraph {
  ConstIndexView offsets, neighbours;
  Kokkos::View<const std::uint8_t*, MemSpace> fixed;
  ConstRealView weights;
  ConstReal3View slideNormal;
  lid_t nNodes() const { return offsets.extent(0) > 0 ? static_cast<lid_t>(offsets.extent(0)) - 1 : 0; }
};

/// \brief One Jacobi sweep: out(i) = in(i) on fixed nodes and on nodes without neighbours, the
/// (weighted) mean of in over the neighbours elsewhere. One thread per node, no atomics, so the
/// result does not depend on the backend or the thread count.
void jacobiSweep(const ExecSpace& exec, const SmoothingGraph& g, const ConstReal3View& in, const Real3View& out);

/// \brief `sweeps` Jacobi sweeps of d in place (ping-pong through `work`, same size as d). No
/// fence at the end.
void jacobiSmooth(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, const Real3View& work,
                  int sweeps);

}  // namespace mfsi
