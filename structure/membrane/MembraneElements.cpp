#include "structure/membrane/MembraneElements.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"

namespace mfsi {

namespace membrane::detail {

KOKKOS_INLINE_FUNCTION int gaussCount(int nv) { return nv == 4 ? 4 : 1; }

/// Gauss point g of a quad (2 x 2, weight 1) or triangle (centroid, weight 1/2).
KOKKOS_INLINE_FUNCTION void gaussPoint(int nv, int g, real& xi, real& eta, real& w) {
  if (nv == 4) {
    const real q = 0.57735026918962576451;
    xi = (g == 0 || g == 3) ? -q : q;
    eta = g < 2 ? -q : q;
    w = 1;
  } else {
    xi = 1.0 / 3.0;
    eta = 1.0 / 3.0;
    w = 0.5;
  }
}

/// Shape functions and parametric derivatives (node order: quads counter-clockwise from (-1,-1);
/// triangles (0,0), (1,0), (0,1)).
KOKKOS_INLINE_FUNCTION void shape(int nv, real xi, real eta, real N[4], real dN[4][2]) {
  if (nv == 4) {
    const real sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int a = 0; a < 4; ++a) {
      N[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
      dN[a][0] = 0.25 * sx[a] * (1 + sy[a] * eta);
      dN[a][1] = 0.25 * sy[a] * (1 + sx[a] * xi);
    }
  } else {
    N[0] = 1 - xi - eta;
    N[1] = xi;
    N[2] = eta;
    N[3] = 0;
    dN[0][0] = -1;
    dN[0][1] = -1;
    dN[1][0] = 1;
    dN[1][1] = 0;
    dN[2][0] = 0;
    dN[2][1] = 1;
    dN[3][0] = 0;
    dN[3][1] = 0;
  }
}

KOKKOS_INLINE_FUNCTION void cross(const real a[3], const real b[3], real c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
KOKKOS_INLINE_FUNCTION real dot3(const real a[3], const real b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Local orthonormal frame (e1, e2) of the reference tangent plane at (xi, eta) and the
/// derivatives dN/ds in it; returns the area Jacobian dA0 / (dxi deta).
KOKKOS_INLINE_FUNCTION real localFrame(int nv, const real X[4][3], real xi, real eta, real N[4], real dNds[4][2],
                                       real e1[3], real e2[3]) {
  real dN[4][2];
  shape(nv, xi, eta, N, dN);
  real G1[3] = {0, 0, 0}, G2[3] = {0, 0, 0};
  for (int a = 0; a < nv; ++a)
    for (int k = 0; k < 3; ++k) {
      G1[k] += dN[a][0] * X[a][k];
      G2[k] += dN[a][1] * X[a][k];
    }
  real n[3];
  cross(G1, G2, n);
  const real ln = kmath::sqrt(dot3(n, n));
  for (int k = 0; k < 3; ++k) n[k] /= ln;
  // e1: global x projected on the plane (y when x is within 60 degrees of the normal), so flat
  // meshes in the xy plane report stresses in global axes.
  real p[3] = {1 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2]};
  if (dot3(p, p) < 0.25) {
    p[0] = -n[1] * n[0];
    p[1] = 1 - n[1] * n[1];
    p[2] = -n[1] * n[2];
  }
  const real lp = kmath::sqrt(dot3(p, p));
  for (int k = 0; k < 3; ++k) e1[k] = p[k] / lp;
  cross(n, e1, e2);
  // A_ab = d s_a / d xi_b; dN/ds = A^{-T} dN/dxi.
  const real A00 = dot3(G1, e1), A01 = dot3(G2, e1), A10 = dot3(G1, e2), A11 = dot3(G2, e2);
  const real det = A00 * A11 - A01 * A10;
  const real i00 = A11 / det, i01 = -A01 / det, i10 = -A10 / det, i11 = A00 / det;  // A^{-1}
  for (int a = 0; a < 4; ++a) {
    dNds[a][0] = dN[a][0] * i00 + dN[a][1] * i10;
    dNds[a][1] = dN[a][0] * i01 + dN[a][1] * i11;
  }
  return det;
}

/// Shape function values at Gauss point g.
KOKKOS_INLINE_FUNCTION void shapeAtGauss(int nv, int g, real N[4]) {
  real xi, eta, w, dN[4][2];
  gaussPoint(nv, g, xi, eta, w);
  shape(nv, xi, eta, N, dN);
}

/// Element node count and current positions x = X + u (slot 3 unused for triangles).
KOKKOS_INLINE_FUNCTION int gatherNodes(const ConstQuad4View& el, const ConstReal3View& X, const ConstRealView& u,
                                       lid_t e, lid_t nodes[4], real x[4][3]) {
  const int nv = el(e, 3) < 0 ? 3 : 4;
  for (int a = 0; a < 4; ++a) {
    nodes[a] = el(e, a);
    for (int k = 0; k < 3; ++k) x[a][k] = a < nv ? X(nodes[a], k) + u(3 * nodes[a] + k) : 0;
  }
  return nv;
}

/// Current tangents g_a = sum_A dN_A/ds_a x_A and the Green-Lagrange strain (Voigt).
KOKKOS_INLINE_FUNCTION void strainAt(int nv, const real dNds[4][2], const real x[4][3], real g[2][3], real E[3]) {
  for (int al = 0; al < 2; ++al)
    for (int k = 0; k < 3; ++k) {
      real s = 0;
      for (int a = 0; a < nv; ++a) s += dNds[a][al] * x[a][k];
      g[al][k] = s;
    }
  E[0] = 0.5 * (dot3(g[0], g[0]) - 1);
  E[1] = 0.5 * (dot3(g[1], g[1]) - 1);
  E[2] = dot3(g[0], g[1]);
}

/// Gauss point pressure from nodal and element values.
KOKKOS_INLINE_FUNCTION real pressureAt(int nv, const real N[4], const lid_t nodes[4], const ConstRealView& pn,
                                       const ConstRealView& pe, lid_t e) {
  real p = pe.extent(0) > 0 ? pe(e) : 0;
  for (int a = 0; a < nv; ++a) p += N[a] * pn(nodes[a]);
  return p;
}

/// Element tangent (material + geometric, optionally + symmetrised follower load stiffness).
KOKKOS_INLINE_FUNCTION void elementTangent(const MembraneElementData& d, const MembranePressureKernel& pr,
                                           bool withPressure, lid_t e, int nv, const lid_t nodes[4],
                                           const real x[4][3], real K[12][12]) {
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) K[i][j] = 0;
  for (int gp = 0; gp < gaussCount(nv); ++gp) {
    real dNds[4][2];
    for (int a = 0; a < 4; ++a)
      for (int al = 0; al < 2; ++al) dNds[a][al] = d.dNds(e, gp, a, al);
    const real w = d.weight(e, gp);
    real g[2][3], E[3], N[3], C[3][3];
    strainAt(nv, dNds, x, g, E);
    d.law.evaluate(E, N, C);
    // Geometric stiffness with the smallest principal force floored (tangent only).
    real s1, s2;
    membrane::principal2(N, s1, s2);
    const real lift = (d.tangentFloor > 0 && s2 < d.tangentFloor) ? d.tangentFloor - s2 : 0;
    const real Ng[3] = {N[0] + lift, N[1] + lift, N[2]};
    real B[4][3][3];  // B[A][voigt][dof]
    for (int a = 0; a < nv; ++a)
      for (int k = 0; k < 3; ++k) {
        B[a][0][k] = dNds[a][0] * g[0][k];
        B[a][1][k] = dNds[a][1] * g[1][k];
        B[a][2][k] = dNds[a][0] * g[1][k] + dNds[a][1] * g[0][k];
      }
    // K is symmetric: accumulate the upper triangle (blocks a <= b) only, mirror at the end.
    for (int b = 0; b < nv; ++b) {
      real CB[3][3];
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) CB[i][k] = C[i][0] * B[b][0][k] + C[i][1] * B[b][1][k] + C[i][2] * B[b][2][k];
      for (int a = 0; a <= b; ++a) {
        const real geo = dNds[a][0] * (Ng[0] * dNds[b][0] + Ng[2] * dNds[b][1]) +
                         dNds[a][1] * (Ng[2] * dNds[b][0] + Ng[1] * dNds[b][1]);
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l)
            K[3 * a + k][3 * b + l] +=
                w * (B[a][0][k] * CB[0][l] + B[a][1][k] * CB[1][l] + B[a][2][k] * CB[2][l] + (k == l ? geo : 0));
      }
    }
    if (withPressure) {
      // d f_ext,A / d x_B = w p N_A (dN_B,1 [g_1]x - dN_B,2 [g_2]x)  (index 0/1 here), with
      // [v]x w = v x w. K gets minus that, symmetrised (see MembranePressureStiffness): entry
      // (i, j) contributes half to the symmetric pair {(i, j), (j, i)}, stored at the upper one.
      real Nsh[4];
      shapeAtGauss(nv, gp, Nsh);
      const real p = pressureAt(nv, Nsh, nodes, pr.nodePressure, pr.elementPressure, e);
      for (int a = 0; a < nv; ++a) {
        const real fa = w * p * (pr.lumped ? 1.0 / nv : Nsh[a]);
        for (int b = 0; b < nv; ++b) {
          // v = dN_B,2 g_1 - dN_B,1 g_2 (0-based: dNds[b][1] g[0] - dNds[b][0] g[1]); [v]x.
          real v[3];
          for (int k = 0; k < 3; ++k) v[k] = dNds[b][1] * g[0][k] - dNds[b][0] * g[1][k];
          const real S[3][3] = {{0, -v[2], v[1]}, {v[2], 0, -v[0]}, {-v[1], v[0], 0}};
          for (int k = 0; k < 3; ++k)
            for (int l = 0; l < 3; ++l) {
              const int i = 3 * a + k, j = 3 * b + l;
              const real kp = -fa * S[k][l];
              if (i <= j) K[i][j] += (i == j ? 1.0 : 0.5) * kp;
              else K[j][i] += 0.5 * kp;
            }
        }
      }
    }
  }
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < i; ++j) K[i][j] = K[j][i];
}

/// Bar (TL truss) internal force on node 1 (node 0 gets the opposite) and its 3 x 3 stiffness
/// block k (the 6 x 6 matrix is [[k, -k], [-k, k]]).
KOKKOS_INLINE_FUNCTION void barForce(const real d[3], real EA, real L0, bool tensionOnly, bool safe, real f[3],
                                     real k[3][3]) {
  const real Egl = (dot3(d, d) - L0 * L0) / (2 * L0 * L0);
  real S = EA * Egl;
  const bool slack = tensionOnly && S < 0;
  if (slack) S = 0;
  for (int i = 0; i < 3; ++i) {
    f[i] = S / L0 * d[i];
    for (int j = 0; j < 3; ++j)
      // safe: a compressed bar's negative geometric term is dropped from the tangent (keeps CG applicable).
      k[i][j] = (slack ? 0 : EA / (L0 * L0 * L0) * d[i] * d[j]) + (i == j ? (safe && S < 0 ? 0 : S) / L0 : 0);
  }
}

/// Spring internal force on the node and its 3 x 3 stiffness.
KOKKOS_INLINE_FUNCTION void springForce(const real v[3], real kst, real L0, bool safe, real f[3], real k[3][3]) {
  const real L = kmath::sqrt(dot3(v, v));
  if (L0 <= 0 || L <= 0) {
    for (int i = 0; i < 3; ++i) {
      f[i] = kst * v[i];
      for (int j = 0; j < 3; ++j) k[i][j] = i == j ? kst : 0;
    }
    return;
  }
  const real t = kst * (L - L0) / L;
  const real tg = (safe && t < 0) ? 0 : t;  // safe: no negative transverse stiffness of a compressed spring
  for (int i = 0; i < 3; ++i) {
    f[i] = t * v[i];
    for (int j = 0; j < 3; ++j) {
      const real ee = v[i] * v[j] / (L * L);
      k[i][j] = kst * ee + tg * ((i == j ? 1 : 0) - ee);
    }
  }
}

}  // namespace membrane::detail

using namespace membrane::detail;

MembraneReferenceGeometry computeMembraneReferenceGeometry(const ExecSpace& exec, const MembraneMesh& mesh) {
  ScopedRegion region("mfsi::structure::membrane::referenceGeometry");
  const lid_t nE = mesh.nElements();
  MembraneReferenceGeometry geo;
  geo.dNds = Kokkos::View<real* [4][4][2], MemSpace>("mfsi::structure::membrane::dNds", nE);
  geo.weight = Kokkos::View<real* [4], MemSpace>("mfsi::structure::membrane::gaussWeight", nE);
  auto el = mesh.elementNodes();
  auto X = mesh.referencePoints();
  auto dNds = geo.dNds;
  auto weight = geo.weight;
  Kokkos::View<int, MemSpace> bad("mfsi::structure::membrane::badJacobian");
  Kokkos::parallel_for(
      "mfsi::structure::membrane::referenceGeometry", RangePolicy(exec, 0, nE), KOKKOS_LAMBDA(lid_t e) {
        const int nv = el(e, 3) < 0 ? 3 : 4;
        real Xe[4][3];
        for (int a = 0; a < 4; ++a)
          for (int k = 0; k < 3; ++k) Xe[a][k] = a < nv ? X(el(e, a), k) : 0;
        for (int gp = 0; gp < 4; ++gp) {
          if (gp >= gaussCount(nv)) {
            weight(e, gp) = 0;
            for (int a = 0; a < 4; ++a) dNds(e, gp, a, 0) = dNds(e, gp, a, 1) = 0;
            continue;
          }
          real xi, eta, w, N[4], dn[4][2], e1[3], e2[3];
          gaussPoint(nv, gp, xi, eta, w);
          const real det = localFrame(nv, Xe, xi, eta, N, dn, e1, e2);
          if (!(det > 0)) bad() = 1;
          weight(e, gp) = w * det;
          for (int a = 0; a < 4; ++a) {
            dNds(e, gp, a, 0) = dn[a][0];
            dNds(e, gp, a, 1) = dn[a][1];
          }
        }
      });
  int hBad = 0;
  Kokkos::deep_copy(exec, hBad, bad);
  exec.fence();
  MFSI_CHECK(hBad == 0, mesh.source() << ": a membrane element has a non-positive Jacobian at a Gauss point "
                                      << "(folded or badly shaped quad)");
  return geo;
}

MembraneElementData makeMembraneElementData(const MembraneMesh& mesh, const MembraneReferenceGeometry& geometry,
                                            const MembraneOptions& options) {
  const auto& m = options.material;
  MembraneElementData d;
  d.elements = mesh.elementNodes();
  d.X = mesh.referencePoints();
  d.dNds = geometry.dNds;
  d.weight = geometry.weight;
  d.law.E = m.youngsModulus;
  d.law.nu = m.poissonRatio;
  d.law.h = m.thickness;
  d.law.preStrain = m.preStress * (1 - m.poissonRatio) / (m.youngsModulus * m.thickness);
  d.law.eta = options.wrinklingStiffnessFraction;
  d.law.residual = options.wrinklingResidualStiffness;
  d.law.wrinkling = options.wrinkling == MembraneWrinklingModel::TensionField;
  d.tangentFloor = options.newton.tangentStressFloor * m.youngsModulus * m.thickness;
  d.density = m.density * m.thickness;
  return d;
}

void membraneResidualItems(const ExecSpace& exec, const MembraneElementData& data,
                           const MembranePressureKernel& pressure, const MembraneLineItems& lines,
                           const ConstRealView& u, const ItemValuesView& residual, const ItemValuesView& external) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  const MembranePressureKernel pr = pressure;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::residual", RangePolicy(exec, 0, nE), KOKKOS_LAMBDA(lid_t e) {
        lid_t nodes[4];
        real x[4][3];
        const int nv = gatherNodes(d.elements, d.X, u, e, nodes, x);
        real fi[12], fe[12];
        for (int i = 0; i < 12; ++i) fi[i] = fe[i] = 0;
        for (int gp = 0; gp < gaussCount(nv); ++gp) {
          real dNds[4][2];
          for (int a = 0; a < 4; ++a)
            for (int al = 0; al < 2; ++al) dNds[a][al] = d.dNds(e, gp, a, al);
          const real w = d.weight(e, gp);
          real g[2][3], E[3], N[3], C[3][3];
          strainAt(nv, dNds, x, g, E);
          d.law.evaluate(E, N, C);
          for (int a = 0; a < nv; ++a)
            for (int k = 0; k < 3; ++k)
              fi[3 * a + k] += w * (N[0] * dNds[a][0] * g[0][k] + N[1] * dNds[a][1] * g[1][k] +
                                    N[2] * (dNds[a][1] * g[0][k] + dNds[a][0] * g[1][k]));
          real Nsh[4];
          shapeAtGauss(nv, gp, Nsh);
          const real p = pressureAt(nv, Nsh, nodes, pr.nodePressure, pr.elementPressure, e);
          if (p == 0) continue;
          real nrm[3];  // area vector per unit reference area: current (follower) or reference (dead)
          if (pr.follower) {
            cross(g[0], g[1], nrm);
          } else {
            real G[2][3], Eref[3], X0[4][3];
            for (int a = 0; a < 4; ++a)
              for (int k = 0; k < 3; ++k) X0[a][k] = a < nv ? d.X(nodes[a], k) : 0;
            strainAt(nv, dNds, X0, G, Eref);
            cross(G[0], G[1], nrm);
          }
          for (int a = 0; a < nv; ++a) {
            const real fa = w * p * (pr.lumped ? 1.0 / nv : Nsh[a]);
            for (int k = 0; k < 3; ++k) fe[3 * a + k] += fa * nrm[k];
          }
        }
        for (int i = 0; i < 12; ++i) {
          residual(e, i) = fe[i] - fi[i];
          external(e, i) = fe[i];
        }
      });
  const lid_t nB = lines.nBars(), nS = lines.nSprings();
  if (nB + nS == 0) return;
  const MembraneLineItems li = lines;
  const ConstReal3View X = data.X;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::residualLines", RangePolicy(exec, 0, nB + nS), KOKKOS_LAMBDA(lid_t i) {
        const lid_t item = nE + i;
        real f[3], k[3][3];
        for (int c = 0; c < 6; ++c) external(item, c) = 0;
        if (i < nB) {
          const lid_t n0 = li.barNodes(i, 0), n1 = li.barNodes(i, 1);
          real dx[3];
          for (int c = 0; c < 3; ++c) dx[c] = X(n1, c) + u(3 * n1 + c) - X(n0, c) - u(3 * n0 + c);
          barForce(dx, li.barEA(i), li.barLength(i), li.barTensionOnly(i) != 0, false, f, k);
          for (int c = 0; c < 3; ++c) {
            residual(item, c) = f[c];
            residual(item, 3 + c) = -f[c];
          }
        } else {
          const lid_t s = i - nB, n = li.springNode(s);
          real v[3];
          for (int c = 0; c < 3; ++c) v[c] = X(n, c) + u(3 * n + c) - li.springAnchor(s, c);
          springForce(v, li.springStiffness(s), li.springRestLength(s), false, f, k);
          for (int c = 0; c < 3; ++c) residual(item, c) = -f[c];
        }
      });
}

namespace {

/// Tangent blocks of the line items, written through `put(item, row, col, value)`.
template <class Put>
void lineTangents(const ExecSpace& exec, const MembraneLineItems& lines, const ConstReal3View& X,
                  const ConstRealView& u, lid_t nE, bool safe, const char* label, const Put& put) {
  const lid_t nB = lines.nBars(), nS = lines.nSprings();
  if (nB + nS == 0) return;
  const MembraneLineItems li = lines;
  Kokkos::parallel_for(
      label, RangePolicy(exec, 0, nB + nS), KOKKOS_LAMBDA(lid_t i) {
        const lid_t item = nE + i;
        real f[3], k[3][3];
        if (i < nB) {
          const lid_t n0 = li.barNodes(i, 0), n1 = li.barNodes(i, 1);
          real dx[3];
          for (int c = 0; c < 3; ++c) dx[c] = X(n1, c) + u(3 * n1 + c) - X(n0, c) - u(3 * n0 + c);
          barForce(dx, li.barEA(i), li.barLength(i), li.barTensionOnly(i) != 0, safe, f, k);
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
              put(item, r, c, k[r][c]);
              put(item, r, 3 + c, -k[r][c]);
              put(item, 3 + r, c, -k[r][c]);
              put(item, 3 + r, 3 + c, k[r][c]);
            }
        } else {
          const lid_t s = i - nB, n = li.springNode(s);
          real v[3];
          for (int c = 0; c < 3; ++c) v[c] = X(n, c) + u(3 * n + c) - li.springAnchor(s, c);
          springForce(v, li.springStiffness(s), li.springRestLength(s), safe, f, k);
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) put(item, r, c, k[r][c]);
        }
      });
}

/// Functor-style writers for `lineTangents` (device-callable, no captured `this`).
struct PutMatrix {
  ItemValuesView K;
  KOKKOS_INLINE_FUNCTION void operator()(lid_t item, int r, int c, real v) const { K(item, r * 12 + c) = v; }
};
struct PutRowSum {
  ItemValuesView S;
  // Row sums are accumulated: the writer is called once per (row, col) of one item by one thread.
  KOKKOS_INLINE_FUNCTION void operator()(lid_t item, int r, int /*c*/, real v) const {
    S(item, r) += v < 0 ? -v : v;
  }
};

}  // namespace

void membraneTangentItems(const ExecSpace& exec, const MembraneElementData& data,
                          const MembranePressureKernel& pressure, const MembraneLineItems& lines,
                          const ConstRealView& u, const ItemValuesView& tangent) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  const MembranePressureKernel pr = pressure;
  const bool withPressure = pressure.follower && pressure.stiffness;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::tangent", RangePolicy(exec, 0, nE), KOKKOS_LAMBDA(lid_t e) {
        lid_t nodes[4];
        real x[4][3];
        const int nv = gatherNodes(d.elements, d.X, u, e, nodes, x);
        real K[12][12];
        elementTangent(d, pr, withPressure, e, nv, nodes, x, K);
        for (int i = 0; i < 12; ++i)
          for (int j = 0; j < 12; ++j) tangent(e, 12 * i + j) = K[i][j];
      });
  lineTangents(exec, lines, data.X, u, nE, data.tangentFloor > 0, "mfsi::structure::membrane::tangentLines",
               PutMatrix{tangent});
}

void membraneLumpedStiffnessItems(const ExecSpace& exec, const MembraneElementData& data,
                                  const MembraneLineItems& lines, const ConstRealView& u,
                                  const ItemValuesView& rowSums) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  const MembranePressureKernel none{};
  Kokkos::parallel_for(
      "mfsi::structure::membrane::lumpedStiffness", RangePolicy(exec, 0, nE), KOKKOS_LAMBDA(lid_t e) {
        lid_t nodes[4];
        real x[4][3];
        const int nv = gatherNodes(d.elements, d.X, u, e, nodes, x);
        real K[12][12];
        elementTangent(d, none, false, e, nv, nodes, x, K);
        for (int i = 0; i < 12; ++i) {
          real s = 0;
          for (int j = 0; j < 12; ++j) s += K[i][j] < 0 ? -K[i][j] : K[i][j];
          rowSums(e, i) = s;
        }
      });
  const lid_t nL = lines.nBars() + lines.nSprings();
  if (nL > 0) {
    Kokkos::parallel_for(
        "mfsi::structure::membrane::lumpedStiffnessZero", RangePolicy(exec, 0, nL), KOKKOS_LAMBDA(lid_t i) {
          for (int r = 0; r < 12; ++r) rowSums(nE + i, r) = 0;
        });
    lineTangents(exec, lines, data.X, u, nE, true, "mfsi::structure::membrane::lumpedStiffnessLines",
                 PutRowSum{rowSums});
  }
}

real membraneVolumeItems(const ExecSpace& exec, const MembraneElementData& data, lid_t nItems,
                         const ConstRealView& u, const ItemValuesView& gradient) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  real volume = 0;
  Kokkos::parallel_reduce(
      "mfsi::structure::membrane::volume", RangePolicy(exec, 0, nItems),
      KOKKOS_LAMBDA(lid_t e, real & v) {
        for (int i = 0; i < 12; ++i) gradient(e, i) = 0;
        if (e >= nE) return;
        lid_t nodes[4];
        real x[4][3];
        const int nv = gatherNodes(d.elements, d.X, u, e, nodes, x);
        for (int gp = 0; gp < gaussCount(nv); ++gp) {
          real dNds[4][2];
          for (int a = 0; a < 4; ++a)
            for (int al = 0; al < 2; ++al) dNds[a][al] = d.dNds(e, gp, a, al);
          const real w = d.weight(e, gp);
          real g[2][3], E[3], nrm[3], Nsh[4];
          strainAt(nv, dNds, x, g, E);
          cross(g[0], g[1], nrm);
          shapeAtGauss(nv, gp, Nsh);
          for (int a = 0; a < nv; ++a)
            for (int k = 0; k < 3; ++k) gradient(e, 3 * a + k) += w * Nsh[a] * nrm[k];
        }
        double hex[8][3];
        for (int a = 0; a < 4; ++a) {
          const int q = a < nv ? a : nv - 1;
          for (int k = 0; k < 3; ++k) {
            hex[a][k] = d.X(nodes[q], k);
            hex[a + 4][k] = x[q][k];
          }
        }
        v += geom::hexVolume(hex);
      },
      volume);
  return volume;
}

void membraneMassItems(const ExecSpace& exec, const MembraneElementData& data, lid_t nItems, bool lumped,
                       const ItemValuesView& mass) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::mass", RangePolicy(exec, 0, nItems), KOKKOS_LAMBDA(lid_t e) {
        const int width = lumped ? 12 : 144;
        for (int i = 0; i < width; ++i) mass(e, i) = 0;
        if (e >= nE) return;
        const int nv = d.elements(e, 3) < 0 ? 3 : 4;
        for (int gp = 0; gp < gaussCount(nv); ++gp) {
          real N[4];
          shapeAtGauss(nv, gp, N);
          const real w = d.weight(e, gp) * d.density;
          for (int a = 0; a < nv; ++a)
            for (int b = 0; b < nv; ++b)
              for (int k = 0; k < 3; ++k) {
                if (lumped)
                  mass(e, 3 * a + k) += w * N[a] * N[b];
                else
                  mass(e, (3 * a + k) * 12 + 3 * b + k) += w * N[a] * N[b];
              }
        }
      });
}

MembraneElementOutput allocateMembraneElementOutput(lid_t nElements) {
  MembraneElementOutput o;
  o.strain = Kokkos::View<real* [3], MemSpace>("mfsi::structure::membrane::out::strain", nElements);
  o.stress = Kokkos::View<real* [3], MemSpace>("mfsi::structure::membrane::out::stress", nElements);
  o.principal1 = RealView("mfsi::structure::membrane::out::principal1", nElements);
  o.principal2 = RealView("mfsi::structure::membrane::out::principal2", nElements);
  o.vonMises = RealView("mfsi::structure::membrane::out::vonMises", nElements);
  o.wrinkleState = Kokkos::View<int*, MemSpace>("mfsi::structure::membrane::out::wrinkleState", nElements);
  o.gaussWrinkleState =
      Kokkos::View<int* [4], MemSpace>("mfsi::structure::membrane::out::gaussWrinkleState", nElements);
  o.basis1 = Real3View("mfsi::structure::membrane::out::basis1", nElements);
  return o;
}

void membraneElementOutput(const ExecSpace& exec, const MembraneElementData& data, const ConstRealView& u,
                           const MembraneElementOutput& out) {
  const lid_t nE = static_cast<lid_t>(data.elements.extent(0));
  const MembraneElementData d = data;
  const MembraneElementOutput o = out;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::output", RangePolicy(exec, 0, nE), KOKKOS_LAMBDA(lid_t e) {
        lid_t nodes[4];
        real x[4][3], X0[4][3];
        const int nv = gatherNodes(d.elements, d.X, u, e, nodes, x);
        for (int a = 0; a < 4; ++a)
          for (int k = 0; k < 3; ++k) X0[a][k] = a < nv ? d.X(nodes[a], k) : 0;
        const real xi = nv == 4 ? 0.0 : 1.0 / 3.0;
        real N[4], dNds[4][2], e1[3], e2[3];
        localFrame(nv, X0, xi, xi, N, dNds, e1, e2);
        real g[2][3], E[3], Nf[3], C[3][3];
        strainAt(nv, dNds, x, g, E);
        const MembraneWrinkleState state = d.law.evaluate(E, Nf, C);
        real S[3];
        for (int i = 0; i < 3; ++i) {
          S[i] = Nf[i] / d.law.h;
          o.strain(e, i) = E[i];
          o.stress(e, i) = S[i];
          o.basis1(e, i) = e1[i];
        }
        real s1, s2;
        membrane::principal2(S, s1, s2);
        o.principal1(e) = s1;
        o.principal2(e) = s2;
        o.vonMises(e) = kmath::sqrt(s1 * s1 - s1 * s2 + s2 * s2);
        o.wrinkleState(e) = static_cast<int>(state);
        // The state at every Gauss point, where the element integrals sample the material law.
        const real gq = 0.57735026918962576451;
        const real gpx[4] = {-gq, gq, -gq, gq}, gpy[4] = {-gq, -gq, gq, gq};
        for (int q = 0; q < 4; ++q) {
          if (nv != 4 && q > 0) {
            o.gaussWrinkleState(e, q) = -1;
            continue;
          }
          const real a = nv == 4 ? gpx[q] : 1.0 / 3.0, b = nv == 4 ? gpy[q] : 1.0 / 3.0;
          real Nq[4], dq[4][2], f1[3], f2[3], gg[2][3], Eq[3], Nfq[3], Cq[3][3];
          localFrame(nv, X0, a, b, Nq, dq, f1, f2);
          strainAt(nv, dq, x, gg, Eq);
          o.gaussWrinkleState(e, q) = static_cast<int>(d.law.evaluate(Eq, Nfq, Cq));
        }
      });
}

}  // namespace mfsi
