#pragma once
/// \file
/// \brief Named phase timers (wall seconds), reported in summary.json.
#include <chrono>
#include <map>
#include <string>

namespace mfsi {

/// \brief Accumulates wall time per named phase. Phases nest freely; each is timed on its own.
class Timers {
 public:
  void add(const std::string& phase, double seconds) { acc_[phase] += seconds; }
  const std::map<std::string, double>& all() const { return acc_; }

 private:
  std::map<std::string, double> acc_;
};

/// \brief Adds the wall time of its scope to a phase (and opens a Kokkos profiling region of the
/// same name when `region` is set). Callers fence before leaving the scope when the phase ends
/// with device work.
class ScopedTimer {
 public:
  ScopedTimer(Timers& timers, std::string phase)
      : timers_(timers), phase_(std::move(phase)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() {
    timers_.add(phase_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  Timers& timers_;
  std::string phase_;
  std::chrono::steady_clock::time_point start_;
};

/// Seconds since an arbitrary epoch (monotonic).
inline double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace mfsi
