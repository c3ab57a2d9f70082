#pragma once
/// \file
/// \brief Closed-form geometry of trilinear hexes and bilinear quads, usable on host and device.
///
/// Why exact formulas: the fluid's ALE scheme computes face swept volumes as trilinear hex volumes;
/// the discrete space-conservation law then holds to round-off only if cell volumes use the same
/// exact trilinear integral. 2-point Gauss rules integrate det J (degree <= 2 per direction) and
/// x det J (degree <= 3) exactly.
#include <Kokkos_Core.hpp>

#include "core/Types.hpp"

namespace mfsi::geom {

KOKKOS_INLINE_FUNCTION void cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

KOKKOS_INLINE_FUNCTION double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

KOKKOS_INLINE_FUNCTION double norm(const double a[3]) { return kmath::sqrt(dot(a, a)); }

KOKKOS_INLINE_FUNCTION double det3(const double a[3], const double b[3], const double c[3]) {
  double bc[3];
  cross(b, c, bc);
  return dot(a, bc);
}

/// Area vector of a bilinear quad, exact: 0.5 (x2 - x0) x (x3 - x1).
KOKKOS_INLINE_FUNCTION void quadAreaVector(const double x[4][3], double s[3]) {
  double d1[3], d2[3];
  for (int k = 0; k < 3; ++k) {
    d1[k] = x[2][k] - x[0][k];
    d2[k] = x[3][k] - x[1][k];
  }
  cross(d1, d2, s);
  for (int k = 0; k < 3; ++k) s[k] *= 0.5;
}

/// Area-weighted centroid of a bilinear quad (2x2 Gauss on |x_xi x x_eta|) and its scalar area.
KOKKOS_INLINE_FUNCTION void quadCentroid(const double x[4][3], double c[3], double& area) {
  const double g = 0.57735026918962576451;  // 1/sqrt(3)
  const double gp[2] = {-g, g};
  area = 0.0;
  c[0] = c[1] = c[2] = 0.0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double xi = gp[i], eta = gp[j];
      const double n[4] = {0.25 * (1 - xi) * (1 - eta), 0.25 * (1 + xi) * (1 - eta), 0.25 * (1 + xi) * (1 + eta),
                           0.25 * (1 - xi) * (1 + eta)};
      const double dxi[4] = {-0.25 * (1 - eta), 0.25 * (1 - eta), 0.25 * (1 + eta), -0.25 * (1 + eta)};
      const double deta[4] = {-0.25 * (1 - xi), -0.25 * (1 + xi), 0.25 * (1 + xi), 0.25 * (1 - xi)};
      double p[3] = {0, 0, 0}, a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
      for (int q = 0; q < 4; ++q)
        for (int k = 0; k < 3; ++k) {
          p[k] += n[q] * x[q][k];
          a[k] += dxi[q] * x[q][k];
          b[k] += deta[q] * x[q][k];
        }
      double ab[3];
      cross(a, b, ab);
      const double w = norm(ab);
      area += w;
      for (int k = 0; k < 3; ++k) c[k] += w * p[k];
    }
  if (area > 0.0) {
    for (int k = 0; k < 3; ++k) c[k] /= area;
  } else {
    for (int k = 0; k < 3; ++k) c[k] = 0.25 * (x[0][k] + x[1][k] + x[2][k] + x[3][k]);
  }
}

/// Exact volume and centroid of a trilinear hex (VTK node order).
KOKKOS_INLINE_FUNCTION void hexVolumeCentroid(const double x[8][3], double& vol, double c[3]) {
  const double g = 0.57735026918962576451;
  const double sx[8] = {-1, 1, 1, -1, -1, 1, 1, -1};
  const double sy[8] = {-1, -1, 1, 1, -1, -1, 1, 1};
  const double sz[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  vol = 0.0;
  c[0] = c[1] = c[2] = 0.0;
  for (int gi = 0; gi < 8; ++gi) {
    const double xi = g * sx[gi], eta = g * sy[gi], zeta = g * sz[gi];
    double p[3] = {0, 0, 0}, jx[3] = {0, 0, 0}, jy[3] = {0, 0, 0}, jz[3] = {0, 0, 0};
    for (int q = 0; q < 8; ++q) {
      const double a = 1 + sx[q] * xi, b = 1 + sy[q] * eta, d = 1 + sz[q] * zeta;
      const double n = 0.125 * a * b * d;
      const double nx = 0.125 * sx[q] * b * d, ny = 0.125 * a * sy[q] * d, nz = 0.125 * a * b * sz[q];
      for (int k = 0; k < 3; ++k) {
        p[k] += n * x[q][k];
        jx[k] += nx * x[q][k];
        jy[k] += ny * x[q][k];
        jz[k] += nz * x[q][k];
      }
    }
    const double dj = det3(jx, jy, jz);
    vol += dj;
    for (int k = 0; k < 3; ++k) c[k] += dj * p[k];
  }
  if (vol != 0.0) {
    for (int k = 0; k < 3; ++k) c[k] /= vol;
  }
}

/// Scaled Jacobian at the 8 corners (det of the unit edge vectors leaving each corner, ordered so a
/// valid right-handed cell is positive); returns the minimum. 1 for a perfect cube, <= 0 inverted.
KOKKOS_INLINE_FUNCTION double hexMinScaledJacobian(const double x[8][3]) {
  // For each corner: the three neighbours along +xi, +eta, +zeta (orientation-preserving).
  const int nb[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};
  double m = 1e300;
  for (int q = 0; q < 8; ++q) {
    double e[3][3];
    double len[3];
    for (int d = 0; d < 3; ++d) {
      for (int k = 0; k < 3; ++k) e[d][k] = x[nb[q][d]][k] - x[q][k];
      len[d] = norm(e[d]);
    }
    const double l = len[0] * len[1] * len[2];
    const double j = l > 0.0 ? det3(e[0], e[1], e[2]) / l : 0.0;
    m = j < m ? j : m;
  }
  return m;
}

}  // namespace mfsi::geom
