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
/// The map x = f0 + f1 xi + f2 eta + f3 xi eta on [-1, 1]^2 (f_k = 1/4 sum_q s_kq x_q) gives x and
/// its derivatives at each point with a few multiply-adds.
KOKKOS_INLINE_FUNCTION void quadCentroid(const double x[4][3], double c[3], double& area) {
  double f[4][3];
  for (int k = 0; k < 3; ++k) {
    f[0][k] = 0.25 * (x[0][k] + x[1][k] + x[2][k] + x[3][k]);
    f[1][k] = 0.25 * (-x[0][k] + x[1][k] + x[2][k] - x[3][k]);  // xi
    f[2][k] = 0.25 * (-x[0][k] - x[1][k] + x[2][k] + x[3][k]);  // eta
    f[3][k] = 0.25 * (x[0][k] - x[1][k] + x[2][k] - x[3][k]);   // xi eta
  }
  const double g = 0.57735026918962576451;  // 1/sqrt(3)
  area = 0.0;
  c[0] = c[1] = c[2] = 0.0;
  for (int gi = 0; gi < 4; ++gi) {
    const double xi = (gi & 1) ? g : -g, eta = (gi & 2) ? g : -g;
    double p[3], a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = f[1][k] + f[3][k] * eta;
      b[k] = f[2][k] + f[3][k] * xi;
      p[k] = f[0][k] + f[1][k] * xi + f[2][k] * eta + f[3][k] * xi * eta;
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
    for (int k = 0; k < 3; ++k) c[k] = f[0][k];
  }
}

/// Coefficients of a trilinear hex's map (VTK node order) on [-1, 1]^3:
/// x = e0 + e1 xi + e2 eta + e3 zeta + e4 xi eta + e5 eta zeta + e6 zeta xi + e7 xi eta zeta,
/// e_k = 1/8 sum_q s_kq x_q with s_kq the product of node q's signs in the monomial's variables.
KOKKOS_INLINE_FUNCTION void hexMapCoefficients(const double x[8][3], double e[8][3]) {
  for (int k = 0; k < 3; ++k) {
    const double p0 = x[0][k], p1 = x[1][k], p2 = x[2][k], p3 = x[3][k];
    const double p4 = x[4][k], p5 = x[5][k], p6 = x[6][k], p7 = x[7][k];
    e[0][k] = 0.125 * (p0 + p1 + p2 + p3 + p4 + p5 + p6 + p7);
    e[1][k] = 0.125 * (-p0 + p1 + p2 - p3 - p4 + p5 + p6 - p7);  // xi
    e[2][k] = 0.125 * (-p0 - p1 + p2 + p3 - p4 - p5 + p6 + p7);  // eta
    e[3][k] = 0.125 * (-p0 - p1 - p2 - p3 + p4 + p5 + p6 + p7);  // zeta
    e[4][k] = 0.125 * (p0 - p1 + p2 - p3 + p4 - p5 + p6 - p7);   // xi eta
    e[5][k] = 0.125 * (p0 + p1 - p2 - p3 - p4 - p5 + p6 + p7);   // eta zeta
    e[6][k] = 0.125 * (p0 - p1 - p2 + p3 - p4 + p5 + p6 - p7);   // zeta xi
    e[7][k] = 0.125 * (-p0 + p1 - p2 + p3 + p4 - p5 + p6 - p7);  // xi eta zeta
  }
}

/// Exact volume of a trilinear hex (VTK node order), in closed form. With the map's coefficients
/// (`hexMapCoefficients`), the integral of det J is
/// 8 [e1, e2, e3] + 8/3 ([e1, e4, e6] - [e2, e4, e5] - [e3, e5, e6]) ([a, b, c] the triple product;
/// every other term integrates to zero, e7 and e0 drop out). The same value as
/// `hexVolumeCentroid`'s Gauss sum to round-off, at about a seventh of its cost.
KOKKOS_INLINE_FUNCTION double hexVolume(const double x[8][3]) {
  double e[8][3];
  hexMapCoefficients(x, e);
  return 8.0 * det3(e[1], e[2], e[3]) +
         (8.0 / 3.0) * (det3(e[1], e[4], e[6]) - det3(e[2], e[4], e[5]) - det3(e[3], e[5], e[6]));
}

/// Exact volume and centroid of a trilinear hex (VTK node order): the 2x2x2 Gauss sums of det J
/// and x det J (exact: det J has degree <= 2 in each coordinate, x det J <= 3), with x and J at
/// each point formed from the map's coefficients e_k (`hexMapCoefficients`) instead of the eight
/// shape functions: about half the operations of the nodal form.
KOKKOS_INLINE_FUNCTION void hexVolumeCentroid(const double x[8][3], double& vol, double c[3]) {
  double e[8][3];
  hexMapCoefficients(x, e);
  const double g = 0.57735026918962576451;
  vol = 0.0;
  c[0] = c[1] = c[2] = 0.0;
  for (int gi = 0; gi < 8; ++gi) {
    const double xi = (gi & 1) ? g : -g, eta = (gi & 2) ? g : -g, zeta = (gi & 4) ? g : -g;
    double jx[3], jy[3], jz[3], p[3];
    for (int k = 0; k < 3; ++k) {
      jx[k] = e[1][k] + e[4][k] * eta + e[6][k] * zeta + e[7][k] * eta * zeta;
      jy[k] = e[2][k] + e[4][k] * xi + e[5][k] * zeta + e[7][k] * zeta * xi;
      jz[k] = e[3][k] + e[5][k] * eta + e[6][k] * xi + e[7][k] * xi * eta;
      p[k] = e[0][k] + e[1][k] * xi + e[2][k] * eta + e[3][k] * zeta + e[4][k] * xi * eta + e[5][k] * eta * zeta +
             e[6][k] * zeta * xi + e[7][k] * xi * eta * zeta;
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
