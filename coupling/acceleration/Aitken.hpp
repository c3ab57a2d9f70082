#pragma once
/// \file
/// \brief Aitken's Delta^2 dynamic relaxation (Irons & Tuck 1969, in the form of Kuettler & Wall 2008).
#include "coupling/acceleration/Acceleration.hpp"

namespace mfsi::coupling {

/// \brief The Aitken relaxation factor sequence: omega_k = -omega_{k-1} r_{k-1}.(r_k - r_{k-1}) /
/// |r_k - r_{k-1}|^2, clamped to [omegaMin, 1]; omegaInit at a step's first iteration. Shared by
/// Aitken and by the quasi-Newton fallback (which keeps it running alongside its own steps).
class AitkenOmega {
 public:
  explicit AitkenOmega(const AccelerationOptions& options) : options_(options), omega_(options.omegaInit) {}
  /// Forget the previous residual: the next omega is omegaInit.
  void reset() {
    havePrevious_ = false;
    omega_ = options_.omegaInit;
  }
  /// The factor for residual r (dots through `acc`), remembering r for the next call.
  double next(const Acceleration& acc, const InterfaceVector& r);
  double omega() const { return omega_; }

 private:
  AccelerationOptions options_;
  double omega_;
  bool havePrevious_ = false;
  InterfaceVector previous_;
};

/// \brief x <- x + omega_k r with Aitken's omega_k.
class Aitken final : public Acceleration {
 public:
  Aitken(const AccelerationOptions& options, std::vector<InterfaceBlock> layout, const SolverComm& comm)
      : Acceleration(options, std::move(layout), comm), omega_(options) {}
  void beginStep() override;

 protected:
  void step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
            AccelerationReport& report) override;
  void restart() override { omega_.reset(); }

 private:
  AitkenOmega omega_;
};

}  // namespace mfsi::coupling
