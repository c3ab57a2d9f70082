#include "structure/rigid/RigidOptions.hpp"

#include "core/Error.hpp"

#include <array>
#include <cmath>

namespace mfsi {

namespace {
constexpr std::array<const char*, 6> kAxisNames{"Px", "Py", "Pz", "Rx", "Ry", "Rz"};
}  // namespace

const char* rigidAxisName(RigidAxis axis) { return kAxisNames[static_cast<std::size_t>(axis)]; }

RigidAxis parseRigidAxis(const std::string& name) {
  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    if (name == kAxisNames[i]) return static_cast<RigidAxis>(i);
  }
  MFSI_CHECK(false, "unknown rigid joint axis '" << name << "' (expected Px, Py, Pz, Rx, Ry or Rz)");
  return RigidAxis::Px;
}

RigidJointType parseRigidJointType(const std::string& name) {
  if (name == "fixed" || name == "null") return RigidJointType::Fixed;
  if (name == "composite") return RigidJointType::Composite;
  if (name == "prescribed") return RigidJointType::Prescribed;
  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    // The single-axis joint types follow Fixed in the enum, in the same order as the axes.
    if (name == kAxisNames[i]) return static_cast<RigidJointType>(i + 1);
  }
  MFSI_CHECK(false, "unknown rigid joint type '"
                        << name << "' (expected fixed, Px, Py, Pz, Rx, Ry, Rz, composite or prescribed)");
  return RigidJointType::Fixed;
}

double RigidTimeFunction::derivative(double t) const {
  if (rate) return rate(t);
  const double h = fdStep;
  return (value(t + h) - value(t - h)) / (2.0 * h);
}

double RigidTimeFunction::secondDerivative(double t) const {
  if (acceleration) return acceleration(t);
  if (rate) {
    const double h = fdStep;
    return (rate(t + h) - rate(t - h)) / (2.0 * h);
  }
  const double h = fdStep;
  return (value(t + h) - 2.0 * value(t) + value(t - h)) / (h * h);
}

RigidTimeFunction RigidTimeFunction::constant(double c) {
  RigidTimeFunction f;
  f.value = [c](double) { return c; };
  f.rate = [](double) { return 0.0; };
  f.acceleration = [](double) { return 0.0; };
  return f;
}

RigidTimeFunction RigidTimeFunction::linear(double a, double b) {
  RigidTimeFunction f;
  f.value = [a, b](double t) { return a + b * t; };
  f.rate = [b](double) { return b; };
  f.acceleration = [](double) { return 0.0; };
  return f;
}

RigidTimeFunction RigidTimeFunction::sine(double amplitude, double omega, double phase, double offset) {
  RigidTimeFunction f;
  f.value = [=](double t) { return offset + amplitude * std::sin(omega * t + phase); };
  f.rate = [=](double t) { return amplitude * omega * std::cos(omega * t + phase); };
  f.acceleration = [=](double t) { return -amplitude * omega * omega * std::sin(omega * t + phase); };
  return f;
}

}  // namespace mfsi
