#pragma once
/// \file
/// \brief Finite-element assembly into a block `CsrMatrix` without atomics: every element (or
/// any other "item" coupling up to 4 nodes: bars, springs) writes its dense matrix / vector into
/// its own slot, then one kernel per row gathers the slots through a precomputed
/// node -> (item, local node) map. The order of the sum in a row is fixed by the map, so the
/// result is bitwise repeatable for any thread count or backend.
///
/// Layout: item i couples nodes `itemNodes(i, 0..3)` (-1 = unused slot, e.g. triangles, bars,
/// springs). Its dense matrix has (4 bs)^2 entries, row-major over (local node a, dof k) x
/// (local node b, dof l): entry ((a bs + k) (4 bs) + b bs + l). Its vector has 4 bs entries.
#include "kernels/CsrMatrix.hpp"

#include <array>
#include <string>
#include <vector>

namespace mfsi {

/// Maximum number of nodes of an assembly item.
inline constexpr int kMaxItemNodes = 4;

/// Per-item dense matrices or vectors (rows: items).
using ItemValuesView = Kokkos::View<real**, MemSpace>;
using ConstItemValuesView = Kokkos::View<const real**, MemSpace>;

/// \brief Node -> (item, local node) map in CSR form: entries `nodeItems[nodeItemOffsets[n] ..
/// nodeItemOffsets[n+1])` are `item * kMaxItemNodes + local`, in increasing item order.
struct NodeItemMap {
  IndexView offsets;  ///< size nNodes + 1
  IndexView entries;  ///< size sum of item sizes
};

/// \brief Host construction of the node -> item map (items with -1 slots allowed).
NodeItemMap buildNodeItemMap(const std::vector<std::array<lid_t, kMaxItemNodes>>& itemNodes, lid_t nNodes,
                             const std::string& label);

/// \brief Everything the gather kernels need: the matrix sparsity, the node -> item map and, per
/// item pair of local nodes (a, b), the offset of node b's column block inside node a's rows.
struct CsrAssemblyMap {
  int blockSize = 1;
  Kokkos::View<lid_t* [kMaxItemNodes], MemSpace> itemNodes;
  NodeItemMap nodeItems;
  /// Offset inside a row: entry (row a*bs+k, column b*bs+l) of item i sits at
  /// `rowPtr[node(a)*bs+k] + columnOffset(i, a*4+b) + l`. -1 for unused slots.
  Kokkos::View<lid_t* [kMaxItemNodes * kMaxItemNodes], MemSpace> columnOffset;
  CsrMatrix pattern;  ///< sparsity (values zeroed); copy it to get matrices sharing the pattern
};

/// \brief Build the block sparsity (every pair of nodes of an item couples) and the gather map.
/// Throws InputError for out-of-range node ids or items without nodes.
CsrAssemblyMap buildCsrAssemblyMap(const std::vector<std::array<lid_t, kMaxItemNodes>>& itemNodes, lid_t nNodes,
                                   int blockSize, const std::string& label);

/// \brief A new matrix on the sparsity of `map` (shared rowPtr/colIdx/diagIdx, own values).
CsrMatrix makeMatrix(const CsrAssemblyMap& map, const std::string& label);

/// \brief out[node*bs + k] = sum over the node's items of itemVectors(item, local*bs + k).
/// `itemVectors` has at least as many rows as items and 4 bs columns. Overwrites `out`.
void gatherItemVectors(const ExecSpace& exec, const CsrAssemblyMap& map, const ConstItemValuesView& itemVectors,
                       const RealView& out);

/// \brief A.values = sum of the item matrices (each row gathered by one thread). A must have the
/// sparsity of `map`.
void gatherItemMatrices(const ExecSpace& exec, const CsrAssemblyMap& map, const ConstItemValuesView& itemMatrices,
                        const CsrMatrix& A);

}  // namespace mfsi
