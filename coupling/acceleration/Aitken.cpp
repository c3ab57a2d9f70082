#include "coupling/acceleration/Aitken.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi::coupling {

double AitkenOmega::next(const Acceleration& acc, const InterfaceVector& r) {
  if (havePrevious_) {
    const InterfaceVector dr = r - previous_;
    const double den = acc.dot(dr, dr);
    const double num = acc.dot(previous_, dr);
    // Guarded denominator: residuals that did not change (to round-off of their size) say nothing
    // about the slope; keep the last omega.
    const double scale = std::max(acc.dot(r, r), acc.dot(previous_, previous_));
    if (std::isfinite(num) && std::isfinite(den) && den > 1e-28 * scale && den > 0) {
      omega_ = std::clamp(-omega_ * num / den, options_.omegaMin, 1.0);
    }
  } else {
    omega_ = options_.omegaInit;
  }
  previous_ = r;
  havePrevious_ = true;
  return omega_;
}

void Aitken::beginStep() {
  Acceleration::beginStep();
  omega_.reset();
}

void Aitken::step(const InterfaceVector& /*xt*/, const InterfaceVector& r, InterfaceVector& x,
                  AccelerationReport& report) {
  report.omega = omega_.next(*this, r);
  x += report.omega * r;
}

}  // namespace mfsi::coupling
