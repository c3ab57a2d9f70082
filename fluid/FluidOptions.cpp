#include "fluid/FluidOptions.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi::fluid {

real TimeFunction::operator()(real t) const {
  const real pi = 3.14159265358979323846;
  switch (kind) {
    case Kind::Constant:
      return 1.0;
    case Kind::OneMinusCos:
      return 1.0 - std::cos(2.0 * pi * t / period);
    case Kind::CosineRamp:
      return t < period ? 0.5 * (1.0 - std::cos(pi * t / period)) : 1.0;
    case Kind::Function:
      return fn ? fn(t) : 1.0;
    case Kind::HalfPowerSine: {
      const real tp = pulseDuration > 0 ? pulseDuration : 0.5 * period;
      real tau = std::fmod(t, period);
      if (tau < 0) tau += period;
      // max(): sin may round to a tiny negative value at the end of a pulse, which a fractional
      // power turns into NaN.
      if (tau < tp) return std::pow(std::max(std::sin(pi * tau / tp), real(0)), exponent);
      if (secondAmplitude != 0 && tau < tp + secondDuration)
        return secondAmplitude * std::pow(std::max(std::sin(pi * (tau - tp) / secondDuration), real(0)), exponent);
      return 0.0;
    }
  }
  return 1.0;
}

bool PatchBC::Valve::open(real t) const {
  if (!(period > 0)) return true;
  real tau = std::fmod(t, period);
  if (tau < 0) tau += period;
  // A step that ends on a switching time (t = openTo, within round-off of the time sum) belongs
  // to the phase that follows it.
  const real eps = 1e-9 * period;
  if (period - tau < eps) tau = 0;
  return tau >= openFrom - eps && tau < openTo - eps;
}

const char* toString(TimeScheme s) {
  switch (s) {
    case TimeScheme::Steady:
      return "steady";
    case TimeScheme::Euler:
      return "Euler";
    case TimeScheme::BDF2:
      return "BDF2";
  }
  return "?";
}

const char* toString(ConvectionScheme s) {
  switch (s) {
    case ConvectionScheme::Upwind:
      return "upwind";
    case ConvectionScheme::Linear:
      return "linear";
    case ConvectionScheme::LimitedLinear:
      return "limitedLinear";
    case ConvectionScheme::VanLeer:
      return "vanLeer";
  }
  return "?";
}

const char* toString(BoundaryType t) {
  switch (t) {
    case BoundaryType::Auto:
      return "auto";
    case BoundaryType::FixedVelocity:
      return "fixedVelocity";
    case BoundaryType::FlowRate:
      return "flowRate";
    case BoundaryType::Wall:
      return "wall";
    case BoundaryType::Slip:
      return "slip";
    case BoundaryType::Empty:
      return "empty";
    case BoundaryType::FixedPressure:
      return "fixedPressure";
    case BoundaryType::Resistance:
      return "resistance";
  }
  return "?";
}

}  // namespace mfsi::fluid
