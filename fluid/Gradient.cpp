#include "fluid/Gradient.hpp"

#include <algorithm>
#include <vector>

namespace mfsi::fluid {

namespace {

template <class G>
KOKKOS_INLINE_FUNCTION std::enable_if_t<static_cast<int>(G::rank) == 2> store(const G& g, lid_t c, int i, int, real v) {
  g(c, i) = v;
}
template <class G>
KOKKOS_INLINE_FUNCTION std::enable_if_t<static_cast<int>(G::rank) == 3> store(const G& g, lid_t c, int i, int j,
                                                                              real v) {
  g(c, i, j) = v;
}

// Solve the symmetric 3x3 system M x = b by Cramer's rule (M is the least-squares normal matrix).
KOKKOS_INLINE_FUNCTION void solve3(const real M[3][3], const real b[3], real x[3]) {
  const real det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                   M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                   M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
  const real inv = det != 0.0 ? 1.0 / det : 0.0;
  x[0] = inv * (b[0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (b[1] * M[2][2] - M[1][2] * b[2]) +
                M[0][2] * (b[1] * M[2][1] - M[1][1] * b[2]));
  x[1] = inv * (M[0][0] * (b[1] * M[2][2] - M[1][2] * b[2]) - b[0] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * b[2] - b[1] * M[2][0]));
  x[2] = inv * (M[0][0] * (M[1][1] * b[2] - b[1] * M[2][1]) - M[0][1] * (M[1][0] * b[2] - b[1] * M[2][0]) +
                b[0] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]));
}

template <int NC, class F, class FB, class G>
void gradientImpl(const ExecSpace& exec, GradientScheme scheme, const HexMesh& mesh, const MeshGeometry& geo,
                  const FvFaceData& fd, const F& phi, const FB& phiB, const G& grad, const ConstIndexView& cells) {
  using detail::comp;
  const bool listed = cells.extent(0) > 0;
  const lid_t count = listed ? static_cast<lid_t>(cells.extent(0)) : mesh.nCells();
  ConstIndexView off = mesh.cellFaceOffsets();
  ConstIndexView cf = mesh.cellFaces();
  ConstIndexView own = mesh.faceOwner();
  ConstIndexView nei = mesh.faceNeighbour();
  ConstReal3View sf = geo.faceArea;
  ConstReal3View cc = geo.cellCentroid;
  ConstReal3View fc = geo.faceCentroid;
  ConstRealView vol = geo.cellVolume;
  ConstRealView w = fd.weight;
  const lid_t nIn = mesh.nInternalFaces();
  if (scheme == GradientScheme::GaussLinear) {
    Kokkos::parallel_for(
        "mfsi::fluid::gradient::gauss", RangePolicy(exec, 0, count), KOKKOS_LAMBDA(lid_t i) {
          const lid_t c = listed ? cells(i) : i;
          real g[3][NC];
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < NC; ++k) g[i][k] = 0;
          for (lid_t e = off(c); e < off(c + 1); ++e) {
            const lid_t f = cf(e);
            const real s = own(f) == c ? 1.0 : -1.0;
            for (int k = 0; k < NC; ++k) {
              real v;
              if (f < nIn)
                v = w(f) * comp(phi, own(f), k) + (1.0 - w(f)) * comp(phi, nei(f), k);
              else
                v = comp(phiB, f - nIn, k);
              for (int i = 0; i < 3; ++i) g[i][k] += s * sf(f, i) * v;
            }
          }
          const real rv = 1.0 / vol(c);
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < NC; ++k) store(grad, c, i, k, g[i][k] * rv);
        });
  } else {
    Kokkos::parallel_for(
        "mfsi::fluid::gradient::leastSquares", RangePolicy(exec, 0, count), KOKKOS_LAMBDA(lid_t ic) {
          const lid_t c = listed ? cells(ic) : ic;
          real M[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
          real b[NC][3];
          for (int k = 0; k < NC; ++k) b[k][0] = b[k][1] = b[k][2] = 0;
          for (lid_t e = off(c); e < off(c + 1); ++e) {
            const lid_t f = cf(e);
            const lid_t other = f < nIn ? (own(f) == c ? nei(f) : own(f)) : -1;
            real d[3];
            for (int i = 0; i < 3; ++i) d[i] = (other >= 0 ? cc(other, i) : fc(f, i)) - cc(c, i);
            const real wt = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) M[i][j] += wt * d[i] * d[j];
            for (int k = 0; k < NC; ++k) {
              const real dv = (other >= 0 ? comp(phi, other, k) : comp(phiB, f - nIn, k)) - comp(phi, c, k);
              for (int i = 0; i < 3; ++i) b[k][i] += wt * d[i] * dv;
            }
          }
          for (int k = 0; k < NC; ++k) {
            real x[3];
            solve3(M, b[k], x);
            for (int i = 0; i < 3; ++i) store(grad, c, i, k, x[i]);
          }
        });
  }
}

}  // namespace

void cellGradient(const ExecSpace& exec, GradientScheme scheme, const HexMesh& mesh, const MeshGeometry& geo,
                  const FvFaceData& fd, const ConstRealView& phi, const ConstRealView& phiB, const Real3View& grad,
                  const ConstIndexView& cells) {
  gradientImpl<1>(exec, scheme, mesh, geo, fd, phi, phiB, grad, cells);
}

void cellGradient(const ExecSpace& exec, GradientScheme scheme, const HexMesh& mesh, const MeshGeometry& geo,
                  const FvFaceData& fd, const ConstReal3View& u, const ConstReal3View& uB, const Tensor3View& grad,
                  const ConstIndexView& cells) {
  gradientImpl<3>(exec, scheme, mesh, geo, fd, u, uB, grad, cells);
}

GradientStencil allocateGradientStencil(const HexMesh& mesh) {
  const lid_t entries = static_cast<lid_t>(mesh.cellFaces().extent(0));
  GradientStencil st;
  st.self = Real3View("mfsi::fluid::gradientStencil::self", mesh.nCells());
  st.other = IndexView("mfsi::fluid::gradientStencil::other", entries);
  st.coef = Real3View("mfsi::fluid::gradientStencil::coef", entries);
  return st;
}

void computeGradientStencil(const ExecSpace& exec, const HexMesh& mesh, const MeshGeometry& geo, const FvFaceData& fd,
                            const GradientStencil& st) {
  ConstIndexView off = mesh.cellFaceOffsets(), cf = mesh.cellFaces(), own = mesh.faceOwner(),
                 nei = mesh.faceNeighbour();
  ConstReal3View sf = geo.faceArea;
  ConstRealView vol = geo.cellVolume, w = fd.weight;
  const lid_t nIn = mesh.nInternalFaces();
  auto self = st.self;
  auto other = st.other;
  auto coef = st.coef;
  Kokkos::parallel_for(
      "mfsi::fluid::gradientStencil::compute", RangePolicy(exec, 0, mesh.nCells()), KOKKOS_LAMBDA(lid_t c) {
        const real rv = 1.0 / vol(c);
        real sc[3] = {0, 0, 0};
        for (lid_t e = off(c); e < off(c + 1); ++e) {
          const lid_t f = cf(e);
          // Face value w phi_owner + (1 - w) phi_neighbour, with S_f pointing out of the owner.
          real wSelf = 1.0, wOther = 0.0, sgn = 1.0;
          if (f < nIn) {
            const bool isOwner = own(f) == c;
            sgn = isOwner ? 1.0 : -1.0;
            wSelf = isOwner ? w(f) : 1.0 - w(f);
            wOther = 1.0 - wSelf;
            other(e) = isOwner ? nei(f) : own(f);
          } else {
            wSelf = 0.0;
            wOther = 1.0;
            other(e) = -(f - nIn + 1);
          }
          for (int i = 0; i < 3; ++i) {
            const real s = sgn * sf(f, i) * rv;
            sc[i] += wSelf * s;
            coef(e, i) = wOther * s;
          }
        }
        for (int i = 0; i < 3; ++i) self(c, i) = sc[i];
      });
}

namespace {

template <int NC, class F, class FB, class G>
void stencilGradient(const ExecSpace& exec, const HexMesh& mesh, const GradientStencil& st, const F& phi,
                     const FB& phiB, const G& grad, const ConstIndexView& cells) {
  using detail::comp;
  const bool listed = cells.extent(0) > 0;
  const lid_t count = listed ? static_cast<lid_t>(cells.extent(0)) : mesh.nCells();
  ConstIndexView off = mesh.cellFaceOffsets(), other = st.other;
  ConstReal3View self = st.self, coef = st.coef;
  Kokkos::parallel_for(
      "mfsi::fluid::gradient::gaussStencil", RangePolicy(exec, 0, count), KOKKOS_LAMBDA(lid_t i) {
        const lid_t c = listed ? cells(i) : i;
        real g[3][NC];
        for (int k = 0; k < NC; ++k) {
          const real v = comp(phi, c, k);
          for (int d = 0; d < 3; ++d) g[d][k] = self(c, d) * v;
        }
        for (lid_t e = off(c); e < off(c + 1); ++e) {
          const lid_t o = other(e);
          for (int k = 0; k < NC; ++k) {
            const real v = o >= 0 ? comp(phi, o, k) : comp(phiB, -o - 1, k);
            for (int d = 0; d < 3; ++d) g[d][k] += coef(e, d) * v;
          }
        }
        for (int d = 0; d < 3; ++d)
          for (int k = 0; k < NC; ++k) store(grad, c, d, k, g[d][k]);
      });
}

}  // namespace

void cellGradient(const ExecSpace& exec, const HexMesh& mesh, const GradientStencil& st, const ConstRealView& phi,
                  const ConstRealView& phiB, const Real3View& grad, const ConstIndexView& cells) {
  stencilGradient<1>(exec, mesh, st, phi, phiB, grad, cells);
}

void cellGradient(const ExecSpace& exec, const HexMesh& mesh, const GradientStencil& st, const ConstReal3View& u,
                  const ConstReal3View& uB, const Tensor3View& grad, const ConstIndexView& cells) {
  stencilGradient<3>(exec, mesh, st, u, uB, grad, cells);
}

IndexView boundaryCells(const HexMesh& mesh) {
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  std::vector<lid_t> cells;
  for (lid_t f = mesh.nInternalFaces(); f < mesh.nFaces(); ++f) cells.push_back(own(f));
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  IndexView out(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::fluid::boundaryCells"), cells.size());
  auto h = Kokkos::create_mirror_view(out);
  for (std::size_t i = 0; i < cells.size(); ++i) h(i) = cells[i];
  Kokkos::deep_copy(out, h);
  return out;
}

}  // namespace mfsi::fluid
