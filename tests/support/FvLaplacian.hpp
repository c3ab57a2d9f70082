#pragma once
// The finite-volume Laplacian as the fluid assembles it, for the CSR and AMG tests: one thread per
// cell walks its faces and writes only its own row (deterministic, no atomics),
// a_PN = -|S|/|d|, a_PP = sum of the face coefficients (pure Neumann).
// A free function, not a TEST body: nvcc compiles device lambdas only in public or free functions
// (a TEST body is a private member of the class the macro makes).
#include "core/HexMesh.hpp"
#include "core/MeshGeometry.hpp"
#include "kernels/CsrBuild.hpp"

namespace mfsi::test {

inline void assembleFvLaplacian(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo,
                                const CellCsr& cc) {
  const auto offs = mesh.cellFaceOffsets();
  const auto faces = mesh.cellFaces();
  const auto owner = mesh.faceOwner(), neigh = mesh.faceNeighbour();
  const auto pn = cc.faceMap.ownerRow, np = cc.faceMap.neighbourRow;
  const auto diag = cc.matrix.diagIdx;
  const auto val = cc.matrix.values;
  const auto area = geo.faceAreaMag;
  const auto cen = geo.cellCentroid;
  const lid_t nIf = mesh.nInternalFaces();
  Kokkos::parallel_for(
      "test::assemble", RangePolicy(exec, 0, mesh.nCells()), KOKKOS_LAMBDA(lid_t c) {
        double d = 0;
        for (lid_t k = offs(c); k < offs(c + 1); ++k) {
          const lid_t f = faces(k);
          if (f >= nIf) continue;
          const lid_t P = owner(f), N = neigh(f);
          const double dx = cen(N, 0) - cen(P, 0), dy = cen(N, 1) - cen(P, 1), dz = cen(N, 2) - cen(P, 2);
          const double coef = area(f) / kmath::sqrt(dx * dx + dy * dy + dz * dz);
          val(c == P ? pn(f) : np(f)) = -coef;
          d += coef;
        }
        val(diag(c)) = d;
      });
  exec.fence();
}

}  // namespace mfsi::test
