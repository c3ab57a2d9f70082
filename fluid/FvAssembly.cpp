#include "fluid/FvAssembly.hpp"

#include "kernels/CsrBuild.hpp"

#include <algorithm>
#include <vector>

namespace mfsi::fluid {

const char* toString(ReductionMode mode) {
  switch (mode) {
    case ReductionMode::Gather:
      return "gather";
    case ReductionMode::Scatter:
      return "scatter";
  }
  return "?";
}

FvSparsity buildSparsity(const HexMesh& mesh) {
  const lid_t nCells = mesh.nCells();
  const lid_t nIn = mesh.nInternalFaces();
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellFaceOffsets());
  auto cf = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellFaces());
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto nei = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNeighbour());

  // Rows: the cell itself plus its face neighbours, sorted and unique (two cells may share more
  // than one face on coarse wrapped meshes; those faces then add into the same entry).
  std::vector<lid_t> rowPtr(nCells + 1, 0);
  std::vector<lid_t> cols;
  std::vector<lid_t> row;
  for (lid_t c = 0; c < nCells; ++c) {
    row.clear();
    row.push_back(c);
    for (lid_t e = off(c); e < off(c + 1); ++e) {
      const lid_t f = cf(e);
      if (f >= nIn) continue;
      row.push_back(own(f) == c ? nei(f) : own(f));
    }
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    cols.insert(cols.end(), row.begin(), row.end());
    rowPtr[c + 1] = static_cast<lid_t>(cols.size());
  }
  auto position = [&](lid_t r, lid_t col) -> lid_t {
    auto b = cols.begin() + rowPtr[r], e = cols.begin() + rowPtr[r + 1];
    auto it = std::lower_bound(b, e, col);
    return static_cast<lid_t>(it - cols.begin());
  };

  FvSparsity s;
  s.nRows = nCells;
  s.runs = buildRowRuns(nCells, rowPtr, cols, "mfsi::fluid::fv");
  s.rowPtr = IndexView("mfsi::fluid::fv::rowPtr", nCells + 1);
  s.colIdx = IndexView("mfsi::fluid::fv::colIdx", cols.size());
  s.diagIdx = IndexView("mfsi::fluid::fv::diagIdx", nCells);
  s.cellFacePos = IndexView("mfsi::fluid::fv::cellFacePos", cf.extent(0));
  s.ownerPos = IndexView("mfsi::fluid::fv::ownerPos", nIn);
  s.neighbourPos = IndexView("mfsi::fluid::fv::neighbourPos", nIn);
  auto hRow = Kokkos::create_mirror_view(s.rowPtr);
  auto hCol = Kokkos::create_mirror_view(s.colIdx);
  auto hDiag = Kokkos::create_mirror_view(s.diagIdx);
  auto hCfp = Kokkos::create_mirror_view(s.cellFacePos);
  auto hOp = Kokkos::create_mirror_view(s.ownerPos);
  auto hNp = Kokkos::create_mirror_view(s.neighbourPos);
  for (lid_t c = 0; c <= nCells; ++c) hRow(c) = rowPtr[c];
  for (std::size_t k = 0; k < cols.size(); ++k) hCol(k) = cols[k];
  for (lid_t c = 0; c < nCells; ++c) {
    hDiag(c) = position(c, c);
    for (lid_t e = off(c); e < off(c + 1); ++e) {
      const lid_t f = cf(e);
      hCfp(e) = f < nIn ? position(c, own(f) == c ? nei(f) : own(f)) : -1;
    }
  }
  for (lid_t f = 0; f < nIn; ++f) {
    hOp(f) = position(own(f), nei(f));
    hNp(f) = position(nei(f), own(f));
  }
  Kokkos::deep_copy(s.rowPtr, hRow);
  Kokkos::deep_copy(s.colIdx, hCol);
  Kokkos::deep_copy(s.diagIdx, hDiag);
  Kokkos::deep_copy(s.cellFacePos, hCfp);
  Kokkos::deep_copy(s.ownerPos, hOp);
  Kokkos::deep_copy(s.neighbourPos, hNp);
  return s;
}

CsrMatrix makeMatrix(const FvSparsity& s, const std::string& label) {
  CsrMatrix A;
  A.nRows = s.nRows;
  A.nCols = s.nRows;
  A.rowPtr = s.rowPtr;
  A.colIdx = s.colIdx;
  A.diagIdx = s.diagIdx;
  A.runs = s.runs;
  A.values = RealView(label, s.colIdx.extent(0));
  return A;
}

FaceCoefficients allocateFaceCoefficients(const HexMesh& mesh, const std::string& prefix) {
  FaceCoefficients fc;
  fc.ownerDiag = RealView(prefix + "::ownerDiag", mesh.nFaces());
  fc.neighbourDiag = RealView(prefix + "::neighbourDiag", mesh.nFaces());
  fc.upper = RealView(prefix + "::upper", mesh.nFaces());
  fc.lower = RealView(prefix + "::lower", mesh.nFaces());
  return fc;
}

void assembleMatrix(const ExecSpace& exec, const HexMesh& mesh, const FvSparsity& s, const FaceCoefficients& fc,
                    const ConstRealView& cellDiag, const CsrMatrix& A, ReductionMode mode) {
  ConstIndexView rowPtr = s.rowPtr;
  ConstIndexView diagIdx = s.diagIdx;
  ConstRealView od = fc.ownerDiag;
  ConstRealView nd = fc.neighbourDiag;
  ConstRealView up = fc.upper;
  ConstRealView lo = fc.lower;
  RealView vals = A.values;
  const lid_t nCells = mesh.nCells();
  if (mode == ReductionMode::Gather) {
    ConstIndexView off = mesh.cellFaceOffsets();
    ConstIndexView cf = mesh.cellFaces();
    ConstIndexView cfp = s.cellFacePos;
    ConstIndexView own = mesh.faceOwner();
    // One thread per row: it owns every entry of the row, so plain stores and adds are race-free.
    Kokkos::parallel_for(
        "mfsi::fluid::fv::assemble::gather", RangePolicy(exec, 0, nCells), KOKKOS_LAMBDA(lid_t c) {
          for (lid_t k = rowPtr(c); k < rowPtr(c + 1); ++k) vals(k) = 0.0;
          real diag = cellDiag(c);
          for (lid_t e = off(c); e < off(c + 1); ++e) {
            const lid_t f = cf(e);
            const bool isOwner = own(f) == c;
            diag += isOwner ? od(f) : nd(f);
            const lid_t p = cfp(e);
            if (p >= 0) vals(p) += isOwner ? up(f) : lo(f);
          }
          vals(diagIdx(c)) += diag;
        });
  } else {
    Kokkos::deep_copy(exec, vals, 0.0);
    Kokkos::parallel_for(
        "mfsi::fluid::fv::assemble::cellDiag", RangePolicy(exec, 0, nCells),
        KOKKOS_LAMBDA(lid_t c) { vals(diagIdx(c)) = cellDiag(c); });
    auto sv = Kokkos::Experimental::create_scatter_view(vals);
    ConstIndexView own = mesh.faceOwner();
    ConstIndexView nei = mesh.faceNeighbour();
    ConstIndexView opos = s.ownerPos;
    ConstIndexView npos = s.neighbourPos;
    const lid_t nIn = mesh.nInternalFaces();
    Kokkos::parallel_for(
        "mfsi::fluid::fv::assemble::scatter", RangePolicy(exec, 0, mesh.nFaces()), KOKKOS_LAMBDA(lid_t f) {
          auto acc = sv.access();
          const lid_t o = own(f);
          acc(diagIdx(o)) += od(f);
          if (f < nIn) {
            const lid_t n = nei(f);
            acc(diagIdx(n)) += nd(f);
            acc(opos(f)) += up(f);
            acc(npos(f)) += lo(f);
          }
        });
    Kokkos::Experimental::contribute(vals, sv);
  }
}

}  // namespace mfsi::fluid
