#pragma once
/// \file
/// \brief Jacobi point-Laplacian smoothing of a nodal vector field over a node -> node graph: the
/// kernel of the mesh motion (coupling/motion), which smooths the displacement of the interior
/// nodes from the reference mesh while boundary nodes keep their prescribed values.
#include "core/Types.hpp"
#include "kernels/Blas.hpp"

#include <cstdint>

namespace mfsi {

/// \brief The graph a sweep walks. `offsets`/`neighbours`: CSR node -> node adjacency (e.g.
/// HexMesh::nodeNodeOffsets / nodeNodes, the cell edges). `fixed(i) != 0`: node i keeps its
/// value. `weights` (optional, one per adjacency entry): the weighted mean sum_j w_ij d_j / sum_j
/// w_ij; empty: the plain mean over the neighbours. `slideNormal` (optional, one per node): a
/// free node with a nonzero unit normal n moves in its tangent plane only (a mesh node sliding along
/// a flat wall): its update is projected, v - (v.n) n, and its normal component keeps its value.
///
/// On one rank's part of a decomposed mesh, `owned` (>= 0) is the number of owned nodes, which
/// come first; the others are ghosts, copies of their owners' values: a sweep or an iteration
/// updates the owned rows only (each owned node's edges are all on the rank, so its row is
/// complete), then refreshes the ghosts through `comm`'s node halo, and every sum goes through
/// `comm`. The default (`owned` = -1, no communicator) is a whole mesh on one rank.
struct SmoothingGraph {
  ConstIndexView offsets, neighbours;
  Kokkos::View<const std::uint8_t*, MemSpace> fixed;
  ConstRealView weights;
  ConstReal3View slideNormal;
  lid_t owned = -1;
  SolverComm comm;
  lid_t nNodes() const { return offsets.extent(0) > 0 ? static_cast<lid_t>(offsets.extent(0)) - 1 : 0; }
  /// The rows a sweep or an iteration updates: the owned nodes.
  lid_t nRows() const { return owned >= 0 ? owned : nNodes(); }
};

/// \brief One Jacobi sweep: out(i) = in(i) on fixed nodes and on nodes without neighbours, the
/// (weighted) mean of in over the neighbours elsewhere. One thread per node, no atomics, so the
/// result does not depend on the backend or the thread count. On a decomposed mesh the owned rows
/// are swept and the ghosts of `out` refreshed from their owners.
void jacobiSweep(const ExecSpace& exec, const SmoothingGraph& g, const ConstReal3View& in, const Real3View& out);

/// \brief `sweeps` Jacobi sweeps of d in place (ping-pong through `work`, same size as d). No
/// fence at the end.
void jacobiSmooth(const ExecSpace& exec, const SmoothingGraph& g, const Real3View& d, const Real3View& work,
                  int sweeps);

}  // namespace mfsi
