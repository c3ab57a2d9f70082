#include "kernels/CsrAssembly.hpp"

#include "core/Error.hpp"
#include "kernels/CsrBuild.hpp"

namespace mfsi {

NodeItemMap buildNodeItemMap(const std::vector<std::array<lid_t, kMaxItemNodes>>& itemNodes, lid_t nNodes,
                             const std::string& label) {
  std::vector<lid_t> offsets(nNodes + 1, 0);
  for (std::size_t i = 0; i < itemNodes.size(); ++i)
    for (int a = 0; a < kMaxItemNodes; ++a) {
      const lid_t n = itemNodes[i][a];
      if (n < 0) continue;
      MFSI_CHECK(n < nNodes, label << ": item " << i << " refers to node " << n << " of " << nNodes);
      ++offsets[n + 1];
    }
  for (lid_t n = 0; n < nNodes; ++n) offsets[n + 1] += offsets[n];
  std::vector<lid_t> entries(offsets[nNodes]);
  std::vector<lid_t> fill(offsets.begin(), offsets.end() - 1);
  // Items in increasing order: the gather order (and so the rounding) is fixed by the item list.
  for (std::size_t i = 0; i < itemNodes.size(); ++i)
    for (int a = 0; a < kMaxItemNodes; ++a)
      if (itemNodes[i][a] >= 0) entries[fill[itemNodes[i][a]]++] = static_cast<lid_t>(i) * kMaxItemNodes + a;
  NodeItemMap m;
  m.offsets = IndexView(label + "::nodeItemOffsets", offsets.size());
  m.entries = IndexView(label + "::nodeItems", entries.size());
  Kokkos::deep_copy(m.offsets, hostView(offsets));
  Kokkos::deep_copy(m.entries, hostView(entries));
  return m;
}

CsrAssemblyMap buildCsrAssemblyMap(const std::vector<std::array<lid_t, kMaxItemNodes>>& itemNodes, lid_t nNodes,
                                   int blockSize, const std::string& label) {
  MFSI_CHECK(blockSize >= 1, label << ": blockSize must be >= 1");
  std::vector<std::vector<lid_t>> adjacency(nNodes);
  for (std::size_t i = 0; i < itemNodes.size(); ++i) {
    int used = 0;
    for (int a = 0; a < kMaxItemNodes; ++a) {
      const lid_t n = itemNodes[i][a];
      MFSI_CHECK(n >= -1 && n < nNodes, label << ": item " << i << " refers to node " << n << " of " << nNodes);
      if (n < 0) continue;
      ++used;
      for (int b = 0; b < kMaxItemNodes; ++b)
        if (itemNodes[i][b] >= 0) adjacency[n].push_back(itemNodes[i][b]);
    }
    MFSI_CHECK(used > 0, label << ": item " << i << " has no node");
  }
  CsrAssemblyMap map;
  map.blockSize = blockSize;
  CsrBuildOptions opt;
  opt.blockSize = blockSize;
  opt.label = label;
  map.pattern = buildCsr(adjacency, opt);
  map.nodeItems = buildNodeItemMap(itemNodes, nNodes, label);

  auto rowPtr = Kokkos::create_mirror_view_and_copy(HostSpace(), map.pattern.rowPtr);
  auto colIdx = Kokkos::create_mirror_view_and_copy(HostSpace(), map.pattern.colIdx);
  std::vector<lid_t> rp(rowPtr.data(), rowPtr.data() + rowPtr.extent(0));
  std::vector<lid_t> ci(colIdx.data(), colIdx.data() + colIdx.extent(0));
  const lid_t nItems = static_cast<lid_t>(itemNodes.size());
  map.itemNodes = Kokkos::View<lid_t* [kMaxItemNodes], MemSpace>(label + "::itemNodes", nItems);
  map.columnOffset =
      Kokkos::View<lid_t* [kMaxItemNodes * kMaxItemNodes], MemSpace>(label + "::columnOffset", nItems);
  auto hNodes = Kokkos::create_mirror_view(map.itemNodes);
  auto hOff = Kokkos::create_mirror_view(map.columnOffset);
  for (lid_t i = 0; i < nItems; ++i)
    for (int a = 0; a < kMaxItemNodes; ++a) {
      hNodes(i, a) = itemNodes[i][a];
      for (int b = 0; b < kMaxItemNodes; ++b) {
        const lid_t na = itemNodes[i][a], nb = itemNodes[i][b];
        // The column block of node b is contiguous and the same in every row of node a's block.
        hOff(i, a * kMaxItemNodes + b) =
            (na < 0 || nb < 0) ? -1 : findEntry(rp, ci, na * blockSize, nb * blockSize) - rp[na * blockSize];
      }
    }
  Kokkos::deep_copy(map.itemNodes, hNodes);
  Kokkos::deep_copy(map.columnOffset, hOff);
  return map;
}

CsrMatrix makeMatrix(const CsrAssemblyMap& map, const std::string& label) {
  CsrMatrix A = map.pattern;
  A.values = RealView(label + "::values", map.pattern.nnz());
  return A;
}

void gatherItemVectors(const ExecSpace& exec, const CsrAssemblyMap& map, const ConstItemValuesView& itemVectors,
                       const RealView& out) {
  const int bs = map.blockSize;
  auto offsets = map.nodeItems.offsets;
  auto entries = map.nodeItems.entries;
  const lid_t nNodes = static_cast<lid_t>(offsets.extent(0)) - 1;
  Kokkos::parallel_for(
      "mfsi::kernels::assembly::gatherVectors", RangePolicy(exec, 0, nNodes * bs), KOKKOS_LAMBDA(lid_t row) {
        const lid_t node = row / bs;
        const int k = row - node * bs;
        real s = 0;
        for (lid_t q = offsets(node); q < offsets(node + 1); ++q) {
          const lid_t item = entries(q) / kMaxItemNodes;
          const int a = entries(q) - item * kMaxItemNodes;
          s += itemVectors(item, a * bs + k);
        }
        out(row) = s;
      });
}

void gatherItemMatrices(const ExecSpace& exec, const CsrAssemblyMap& map, const ConstItemValuesView& itemMatrices,
                        const CsrMatrix& A) {
  const int bs = map.blockSize;
  const int width = kMaxItemNodes * bs;
  auto offsets = map.nodeItems.offsets;
  auto entries = map.nodeItems.entries;
  auto nodes = map.itemNodes;
  auto colOff = map.columnOffset;
  auto rowPtr = A.rowPtr;
  auto values = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::assembly::gatherMatrices", RangePolicy(exec, 0, A.nRows), KOKKOS_LAMBDA(lid_t row) {
        for (lid_t p = rowPtr(row); p < rowPtr(row + 1); ++p) values(p) = 0;
        const lid_t node = row / bs;
        const int k = row - node * bs;
        for (lid_t q = offsets(node); q < offsets(node + 1); ++q) {
          const lid_t item = entries(q) / kMaxItemNodes;
          const int a = entries(q) - item * kMaxItemNodes;
          const int r = (a * bs + k) * width;
          for (int b = 0; b < kMaxItemNodes; ++b) {
            if (nodes(item, b) < 0) continue;
            const lid_t base = rowPtr(row) + colOff(item, a * kMaxItemNodes + b);
            for (int l = 0; l < bs; ++l) values(base + l) += itemMatrices(item, r + b * bs + l);
          }
        }
      });
}

}  // namespace mfsi
