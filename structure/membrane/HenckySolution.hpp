#pragma once
/// \file
/// \brief Hencky's problem solved exactly: a clamped circular membrane (radius a, thickness h,
/// Young's modulus E, Poisson ratio nu) under uniform pressure p, Foppl membrane theory.
///
/// With x = r / a and the radial stress resultant N_r = C S(x), C = (E h p^2 a^2)^(1/3) / 2, the
/// equations (vertical equilibrium N_r w' = -p r / 2 and compatibility
/// r (N_r + N_theta)' = -(E h / 2) w'^2, N_theta = (r N_r)') become S^2 (S'' + 3 S' / x) = -1. Its
/// power series S = sum_n s_n x^(2n) follows from s_0 by a recurrence; s_0 is the root of the edge
/// condition u(a) = 0, i.e. (1 - nu) S(1) + S'(1) = 0; and the centre deflection is
///   w0 = C_w a (p a / (E h))^(1/3),  C_w = integral_0^1 x / S(x) dx,
/// integrated term by term from the series of 1 / S. The series converges beyond x = 1 (its last
/// terms are below 1e-60 at 100 terms), so C_w is exact to round-off for any nu in (-1, 0.5].
/// Chien's (1948) corrected table (nu = 0, 0.1, ..., 0.5) is reproduced to its 4 digits.
namespace mfsi {

struct HenckySolution {
  double deflection = 0;  ///< C_w of w0 = C_w a (p a / (E h))^(1/3)
  double stress = 0;      ///< C_sigma of the centre stress sigma0 = C_sigma (E p^2 a^2 / h^2)^(1/3)
  /// Hencky's b0 (= 4 C_sigma), the leading coefficient of his stress series.
  double b0() const { return 4 * stress; }
};

/// \brief The exact solution for Poisson ratio `nu` in (-1, 0.5]. Throws InputError outside.
HenckySolution henckySolution(double nu);

}  // namespace mfsi
