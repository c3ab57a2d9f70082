#include "kernels/CsrBuild.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <map>

namespace mfsi {

namespace {

/// Copy host CSR arrays into a device CsrMatrix (values zeroed, diagIdx found by search).
CsrMatrix upload(lid_t nRows, lid_t nCols, const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx,
                 const std::string& label) {
  CsrMatrix A;
  A.nRows = nRows;
  A.nCols = nCols;
  A.rowPtr = IndexView(label + "::rowPtr", nRows + 1);
  A.colIdx = IndexView(label + "::colIdx", colIdx.size());
  A.diagIdx = IndexView(label + "::diagIdx", nRows);
  A.values = RealView(label + "::values", colIdx.size());
  std::vector<lid_t> diag(nRows);
  for (lid_t i = 0; i < nRows; ++i) diag[i] = findEntry(rowPtr, colIdx, i, i);
  Kokkos::deep_copy(A.rowPtr, hostView(rowPtr));
  Kokkos::deep_copy(A.colIdx, hostView(colIdx));
  Kokkos::deep_copy(A.diagIdx, hostView(diag));
  A.runs = buildRowRuns(nRows, rowPtr, colIdx, label);
  return A;
}

/// Sort and unique each row's columns in place, expand blocks, add diagonals.
CsrMatrix finish(lid_t nNodes, const std::vector<lid_t>& offsets, const std::vector<lid_t>& neighbours,
                 const CsrBuildOptions& opt) {
  MFSI_CHECK(opt.blockSize >= 1, "buildCsr: blockSize must be >= 1, got " << opt.blockSize);
  const lid_t bs = opt.blockSize;
  const lid_t nRows = nNodes * bs;
  const lid_t nCols = opt.nCols < 0 ? nRows : opt.nCols;
  MFSI_CHECK(nCols >= 0, "buildCsr: nCols must be >= 0");
  const lid_t nColNodes = nCols / bs;
  std::vector<lid_t> rowPtr(nRows + 1, 0), colIdx;
  std::vector<lid_t> cols;
  for (lid_t i = 0; i < nNodes; ++i) {
    cols.assign(neighbours.begin() + offsets[i], neighbours.begin() + offsets[i + 1]);
    for (lid_t c : cols)
      MFSI_CHECK(c >= 0 && c < nColNodes,
                 "buildCsr: row " << i << " lists column " << c << " outside [0, " << nColNodes << ")");
    if (opt.addDiagonal) cols.push_back(i);
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    for (lid_t a = 0; a < bs; ++a) {
      for (lid_t c : cols)
        for (lid_t b = 0; b < bs; ++b) colIdx.push_back(c * bs + b);
      rowPtr[i * bs + a + 1] = static_cast<lid_t>(colIdx.size());
    }
  }
  return upload(nRows, nCols, rowPtr, colIdx, opt.label);
}

}  // namespace

/// Row runs of a sparsity (see CsrRowRuns), or none when the average run would be shorter than
/// kMinMeanRun rows (the run kernels then gain nothing over the row kernels).
CsrRowRuns buildRowRuns(lid_t nRows, const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx,
                        const std::string& label) {
  constexpr double kMinMeanRun = 8.0;
  CsrRowRuns runs;
  if (nRows == 0) return runs;
  std::map<std::vector<lid_t>, lid_t> patterns;  // relative columns -> where they sit in `offsets`
  std::vector<lid_t> start, offsetsAt, offsets, blockStart, key, previous;
  for (lid_t i = 0; i < nRows; ++i) {
    key.assign(colIdx.begin() + rowPtr[i], colIdx.begin() + rowPtr[i + 1]);
    for (lid_t& c : key) c -= i;
    const bool newBlock = i % kRowBlock == 0;
    if (newBlock) blockStart.push_back(static_cast<lid_t>(start.size()));
    if (newBlock || key != previous) {
      const auto [it, added] = patterns.emplace(key, static_cast<lid_t>(offsets.size()));
      if (added) offsets.insert(offsets.end(), key.begin(), key.end());
      start.push_back(i);
      offsetsAt.push_back(it->second);
      previous = key;
    }
  }
  if (static_cast<double>(nRows) < kMinMeanRun * static_cast<double>(start.size())) return runs;
  start.push_back(nRows);
  blockStart.push_back(static_cast<lid_t>(offsetsAt.size()));
  runs.count = static_cast<lid_t>(offsetsAt.size());
  runs.start = toDevice(start, label + "::runs::start");
  runs.offsetsAt = toDevice(offsetsAt, label + "::runs::offsetsAt");
  runs.offsets = toDevice(offsets.empty() ? std::vector<lid_t>{0} : offsets, label + "::runs::offsets");
  runs.blockStart = toDevice(blockStart, label + "::runs::blockStart");
  return runs;
}

CsrGhostSplit buildGhostSplit(lid_t nRows, lid_t firstGhost, const IndexView& rowPtr, const IndexView& colIdx,
                              const CsrRowRuns& runs, const std::string& label) {
  const auto ptr = Kokkos::create_mirror_view_and_copy(HostSpace(), rowPtr);
  const auto col = Kokkos::create_mirror_view_and_copy(HostSpace(), colIdx);
  std::vector<char> ghostRow(static_cast<std::size_t>(nRows), 0);
  bool any = false;
  for (lid_t i = 0; i < nRows; ++i)
    for (lid_t k = ptr(i); k < ptr(i + 1); ++k)
      if (col(k) >= firstGhost) {
        ghostRow[i] = 1;
        any = true;
        break;
      }
  CsrGhostSplit split;
  if (!any) return split;
  // Parts [first, last) of 0..count-1 whose rows are [begin(p), end(p)), each listed as interior or boundary.
  auto part = [&](lid_t count, auto begin, auto end, IndexView (&out)[2], const char* what) {
    std::vector<lid_t> lists[2];
    for (lid_t p = 0; p < count; ++p) {
      bool ghost = false;
      for (lid_t i = begin(p); i < end(p) && !ghost; ++i) ghost = ghostRow[i] != 0;
      lists[ghost ? CsrGhostSplit::kBoundary : CsrGhostSplit::kInterior].push_back(p);
    }
    for (int s = 0; s < 2; ++s) out[s] = toDevice(lists[s], label + "::ghostSplit::" + what);
  };
  part(
      nRows, [](lid_t i) { return i; }, [](lid_t i) { return i + 1; }, split.rows, "rows");
  part(
      (nRows + kRowBlock - 1) / kRowBlock, [](lid_t b) { return b * kRowBlock; },
      [&](lid_t b) { return std::min<lid_t>(nRows, (b + 1) * kRowBlock); }, split.blocks, "blocks");
  if (runs.count > 0) {
    const auto start = Kokkos::create_mirror_view_and_copy(HostSpace(), runs.start);
    part(
        runs.count, [&](lid_t r) { return start(r); }, [&](lid_t r) { return start(r + 1); }, split.runs, "runs");
  }
  return split;
}

lid_t findEntry(const std::vector<lid_t>& rowPtr, const std::vector<lid_t>& colIdx, lid_t row, lid_t col) {
  const auto begin = colIdx.begin() + rowPtr[row], end = colIdx.begin() + rowPtr[row + 1];
  const auto it = std::lower_bound(begin, end, col);
  return (it != end && *it == col) ? static_cast<lid_t>(it - colIdx.begin()) : -1;
}

CsrMatrix buildCsr(const std::vector<std::vector<lid_t>>& adjacency, const CsrBuildOptions& options) {
  std::vector<lid_t> offsets(adjacency.size() + 1, 0), neighbours;
  for (std::size_t i = 0; i < adjacency.size(); ++i) {
    neighbours.insert(neighbours.end(), adjacency[i].begin(), adjacency[i].end());
    offsets[i + 1] = static_cast<lid_t>(neighbours.size());
  }
  return finish(static_cast<lid_t>(adjacency.size()), offsets, neighbours, options);
}

CsrMatrix buildCsr(const std::vector<lid_t>& offsets, const std::vector<lid_t>& neighbours,
                   const CsrBuildOptions& options) {
  MFSI_CHECK(!offsets.empty() && offsets.front() == 0 && offsets.back() == static_cast<lid_t>(neighbours.size()),
             "buildCsr: offsets must start at 0 and end at neighbours.size()");
  for (std::size_t i = 1; i < offsets.size(); ++i)
    MFSI_CHECK(offsets[i] >= offsets[i - 1], "buildCsr: offsets decrease at row " << i - 1);
  return finish(static_cast<lid_t>(offsets.size()) - 1, offsets, neighbours, options);
}

CellCsr buildCellCsr(const HexMesh& mesh, const std::string& label) {
  const lid_t nRows = mesh.nOwnedCells(), nCols = mesh.nCells(), nIf = mesh.nInternalFaces();
  auto owner = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto neigh = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNeighbour());

  // Rows hold the diagonal and every neighbour across an internal face.
  std::vector<lid_t> count(nRows + 1, 0);
  for (lid_t f = 0; f < nIf; ++f) {
    if (owner(f) < nRows) ++count[owner(f) + 1];
    if (neigh(f) < nRows) ++count[neigh(f) + 1];
  }
  std::vector<lid_t> offsets(nRows + 1, 0);
  for (lid_t i = 0; i < nRows; ++i) offsets[i + 1] = offsets[i] + count[i + 1];
  std::vector<lid_t> neighbours(offsets[nRows]);
  std::vector<lid_t> fill(offsets.begin(), offsets.end() - 1);
  for (lid_t f = 0; f < nIf; ++f) {
    if (owner(f) < nRows) neighbours[fill[owner(f)]++] = neigh(f);
    if (neigh(f) < nRows) neighbours[fill[neigh(f)]++] = owner(f);
  }
  CsrBuildOptions opt;
  opt.nCols = nCols;
  opt.label = label;
  CellCsr out;
  out.matrix = finish(nRows, offsets, neighbours, opt);
  if (nCols > nRows)
    out.matrix.ghostSplit = buildGhostSplit(nRows, nRows, out.matrix.rowPtr, out.matrix.colIdx, out.matrix.runs, label);

  // Face map: search once here so that assembly never searches.
  auto rowPtr = Kokkos::create_mirror_view_and_copy(HostSpace(), out.matrix.rowPtr);
  auto colIdx = Kokkos::create_mirror_view_and_copy(HostSpace(), out.matrix.colIdx);
  std::vector<lid_t> rp(rowPtr.data(), rowPtr.data() + rowPtr.extent(0));
  std::vector<lid_t> ci(colIdx.data(), colIdx.data() + colIdx.extent(0));
  auto ownerRow = Kokkos::View<lid_t*, HostSpace>("mfsi::kernels::cellCsr::ownerRow", nIf);
  auto neighbourRow = Kokkos::View<lid_t*, HostSpace>("mfsi::kernels::cellCsr::neighbourRow", nIf);
  for (lid_t f = 0; f < nIf; ++f) {
    ownerRow(f) = owner(f) < nRows ? findEntry(rp, ci, owner(f), neigh(f)) : -1;
    neighbourRow(f) = neigh(f) < nRows ? findEntry(rp, ci, neigh(f), owner(f)) : -1;
  }
  out.faceMap.ownerRow = IndexView(label + "::faceOwnerRow", nIf);
  out.faceMap.neighbourRow = IndexView(label + "::faceNeighbourRow", nIf);
  Kokkos::deep_copy(out.faceMap.ownerRow, ownerRow);
  Kokkos::deep_copy(out.faceMap.neighbourRow, neighbourRow);
  return out;
}

CsrMatrix buildPoisson7(std::array<lid_t, 3> n, ModelBoundary boundary, const std::string& label) {
  MFSI_CHECK(n[0] > 0 && n[1] > 0 && n[2] > 0, "buildPoisson7: cell counts must be positive");
  const lid_t nx = n[0], ny = n[1], nz = n[2];
  const lid_t nCells = nx * ny * nz;
  // Neighbour offsets in the order of increasing column index: -z, -y, -x, +x, +y, +z.
  std::vector<lid_t> offsets(nCells + 1, 0), neighbours;
  neighbours.reserve(6 * static_cast<std::size_t>(nCells));
  for (lid_t k = 0; k < nz; ++k)
    for (lid_t j = 0; j < ny; ++j)
      for (lid_t i = 0; i < nx; ++i) {
        const lid_t c = i + nx * (j + ny * k);
        if (k > 0) neighbours.push_back(c - nx * ny);
        if (j > 0) neighbours.push_back(c - nx);
        if (i > 0) neighbours.push_back(c - 1);
        if (i + 1 < nx) neighbours.push_back(c + 1);
        if (j + 1 < ny) neighbours.push_back(c + nx);
        if (k + 1 < nz) neighbours.push_back(c + nx * ny);
        offsets[c + 1] = static_cast<lid_t>(neighbours.size());
      }
  CsrBuildOptions opt;
  opt.label = label;
  CsrMatrix A = finish(nCells, offsets, neighbours, opt);
  // Values: -1 off the diagonal; diagonal = internal faces + 2 per Dirichlet boundary face.
  const real dirichlet = boundary == ModelBoundary::Dirichlet ? 2.0 : 0.0;
  const ConstIndexView rowPtr = A.rowPtr, colIdx = A.colIdx;
  const RealView val = A.values;
  Kokkos::parallel_for(
      "mfsi::kernels::csr::poisson7Values", RangePolicy(ExecSpace(), 0, nCells), KOKKOS_LAMBDA(lid_t c) {
        const lid_t nOff = rowPtr(c + 1) - rowPtr(c) - 1;
        for (lid_t k = rowPtr(c); k < rowPtr(c + 1); ++k)
          val(k) = colIdx(k) == c ? nOff + dirichlet * (6 - nOff) : -1.0;
      });
  Kokkos::fence();
  return A;
}

}  // namespace mfsi
