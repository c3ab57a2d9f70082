#include "coupling/acceleration/Acceleration.hpp"

#include "core/Error.hpp"
#include "coupling/acceleration/Aitken.hpp"
#include "coupling/acceleration/QuasiNewton.hpp"

#include <cmath>

namespace mfsi::coupling {

Acceleration::Acceleration(const AccelerationOptions& options, std::vector<InterfaceBlock> layout,
                           const SolverComm& comm)
    : options_(options), layout_(std::move(layout)), comm_(comm) {
  for (const auto& b : layout_) {
    MFSI_CHECK(b.offset == size_ && b.size >= 0, "interface block '" << b.name << "' does not follow the previous one");
    size_ += b.size;
  }
  MFSI_CHECK(options_.omegaInit > 0 && options_.omegaInit <= 1, "coupling.omegaInit must be in (0, 1]");
  MFSI_CHECK(options_.omegaMin > 0 && options_.omegaMin <= 1, "coupling.omegaMin must be in (0, 1]");
}

double Acceleration::dot(const InterfaceVector& a, const InterfaceVector& b) const {
  return comm_.globalSum(a.dot(b));
}

double Acceleration::norm(const InterfaceVector& a) const { return std::sqrt(dot(a, a)); }

void Acceleration::beginStep() {
  iteration_ = 0;
  bestResidual_ = 0;
  sinceBest_ = 0;
}

AccelerationReport Acceleration::update(const InterfaceVector& xt, InterfaceVector& x) {
  MFSI_CHECK(xt.size() == size_ && x.size() == size_, "interface vectors of size " << xt.size() << " and "
                                                                                    << x.size() << " for a layout of "
                                                                                    << size_);
  ++iteration_;
  const InterfaceVector r = xt - x;
  AccelerationReport report;
  report.residualNorm = norm(r);
  if (iteration_ == 1 || report.residualNorm < bestResidual_) {
    bestResidual_ = report.residualNorm;
    sinceBest_ = 0;
  } else if (options_.stallIterations > 0 && ++sinceBest_ >= options_.stallIterations) {
    restart();
    report.restarted = true;
    bestResidual_ = report.residualNorm;
    sinceBest_ = 0;
  }
  step(xt, r, x, report);
  return report;
}

void ConstantRelaxation::step(const InterfaceVector& /*xt*/, const InterfaceVector& r, InterfaceVector& x,
                              AccelerationReport& report) {
  report.omega = options_.omegaInit;
  x += report.omega * r;
}

std::unique_ptr<Acceleration> makeAcceleration(const AccelerationOptions& options,
                                               std::vector<InterfaceBlock> layout, const SolverComm& comm) {
  if (options.method == AccelerationMethod::IqnIls || options.iqnMaxCols > 0) {
    AccelerationOptions o = options;
    o.method = AccelerationMethod::IqnIls;
    if (o.iqnJacobian == IqnJacobian::MultiVector) return std::make_unique<IqnImvj>(o, std::move(layout), comm);
    return std::make_unique<IqnIls>(o, std::move(layout), comm);
  }
  if (options.method == AccelerationMethod::Aitken) return std::make_unique<Aitken>(options, std::move(layout), comm);
  return std::make_unique<ConstantRelaxation>(options, std::move(layout), comm);
}

}  // namespace mfsi::coupling
