#include "structure/membrane/HenckySolution.hpp"

#include "core/Error.hpp"

#include <cmath>
#include <vector>

namespace mfsi {

namespace {

constexpr int kTerms = 100;

/// The coefficients s_0 .. s_kTerms of S from s_0: the coefficient of x^(2k) of
/// S^2 (S'' + 3 S' / x) = S^2 sum_m 4 (m + 1)(m + 2) s_(m+1) x^(2m) is -1 for k = 0 and 0 after.
std::vector<double> stressSeries(double s0) {
  std::vector<double> s = {s0}, sq = {s0 * s0};  // sq: the coefficients of S^2
  for (int k = 0; k < kTerms; ++k) {
    double rest = k == 0 ? -1.0 : 0.0;
    for (int i = 1; i <= k; ++i) rest -= sq[i] * 4.0 * (k - i + 1) * (k - i + 2) * s[k - i + 1];
    s.push_back(rest / (sq[0] * 4.0 * (k + 1) * (k + 2)));
    const int n = k + 1;
    double c = 0;
    for (int i = 0; i <= n; ++i) c += s[i] * s[n - i];
    sq.push_back(c);
  }
  return s;
}

/// (1 - nu) S(1) + S'(1): zero when the edge does not move radially.
double edgeCondition(double s0, double nu) {
  const std::vector<double> s = stressSeries(s0);
  double f = 0;
  for (std::size_t n = 0; n < s.size(); ++n) f += s[n] * ((1 - nu) + 2.0 * n);
  return f;
}

}  // namespace

HenckySolution henckySolution(double nu) {
  if (!(nu > -1 && nu <= 0.5))
    throw InputError("Hencky's solution: the Poisson ratio must be in (-1, 0.5], got " + std::to_string(nu));
  // S(0) grows with nu; the edge condition changes sign once on [0.2, 3] for every nu in range.
  double lo = 0.2, hi = 3.0;
  const double flo = edgeCondition(lo, nu);
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if ((edgeCondition(mid, nu) > 0) == (flo > 0))
      lo = mid;
    else
      hi = mid;
  }
  const double s0 = 0.5 * (lo + hi);
  const std::vector<double> s = stressSeries(s0);
  // 1 / S = sum t_n x^(2n): t_0 = 1 / s_0, t_n = -(sum_{i=1..n} s_i t_(n-i)) / s_0; then
  // integral_0^1 x^(2n+1) dx = 1 / (2n + 2).
  std::vector<double> t = {1 / s0};
  double cw = t[0] / 2;
  for (int n = 1; n <= kTerms; ++n) {
    double c = 0;
    for (int i = 1; i <= n; ++i) c -= s[i] * t[n - i];
    t.push_back(c / s0);
    cw += t[n] / (2.0 * n + 2);
  }
  HenckySolution h;
  h.deflection = cw;
  // sigma0 = N_r(0) / h = C s_0 / h = (E p^2 a^2 / h^2)^(1/3) s_0 / 2.
  h.stress = s0 / 2;
  return h;
}

}  // namespace mfsi
