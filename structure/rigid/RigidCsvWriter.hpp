#pragma once
/// \file
/// \brief Per-step CSV report of a rigid body system: the header once, then one line per body
/// per call (time, CoM, Euler angles, rotation matrix, velocities, accelerations, loads).
#include "structure/rigid/RigidBodySystem.hpp"

#include <ostream>

namespace mfsi {

/// \brief Writes `RigidBodySystem` rows to a stream, with the header before the first row.
/// The stream must outlive the writer.
class RigidCsvWriter {
 public:
  explicit RigidCsvWriter(std::ostream& os) : os_(os) {}

  /// \brief Append one line per body for the system's latest state (header first on the first call).
  void write(const RigidBodySystem& system) {
    if (!headerWritten_) {
      RigidBodySystem::writeCsvHeader(os_);
      headerWritten_ = true;
    }
    system.writeCsvRows(os_);
  }

 private:
  std::ostream& os_;
  bool headerWritten_ = false;
};

}  // namespace mfsi
