#pragma once
/// \file
/// \brief The one tolerance helper of the test suite: explicit absolute and relative tolerances,
/// failures name the index and both values.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

namespace mfsi::test {

/// \brief Tolerance pair: |a - b| <= abs + rel * max(|a|, |b|).
struct Tol {
  double abs = 0.0;
  double rel = 0.0;
};

inline ::testing::AssertionResult near(double actual, double expected, Tol tol, const std::string& what = "") {
  const double err = std::abs(actual - expected);
  const double bound = tol.abs + tol.rel * std::max(std::abs(actual), std::abs(expected));
  if (std::isfinite(actual) && err <= bound) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(15);
  os << (what.empty() ? "" : what + ": ") << "actual " << actual << " vs expected " << expected << " (|diff| " << err
     << " > bound " << bound << " = abs " << tol.abs << " + rel " << tol.rel << ")";
  return ::testing::AssertionFailure() << os.str();
}

/// \brief Compare two indexable sequences of length n; reports the first failing index.
template <class A, class B>
::testing::AssertionResult allNear(const A& actual, const B& expected, std::size_t n, Tol tol,
                                   const std::string& what = "") {
  for (std::size_t i = 0; i < n; ++i) {
    auto r = near(actual[i], expected[i], tol);
    if (!r) return ::testing::AssertionFailure() << what << "[" << i << "] " << r.message();
  }
  return ::testing::AssertionSuccess();
}

}  // namespace mfsi::test
