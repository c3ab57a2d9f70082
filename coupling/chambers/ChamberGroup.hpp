#pragma once
/// \file
/// \brief Closed chambers that share membranes, and the linear algebra of their volume split.
///
/// A closed chamber (a fluid region no pressure boundary reaches, or a lumped gas chamber) is
/// bounded by membranes whose volume constraints carry its pressure as a multiplier. Chambers
/// that share a membrane (one between two closed regions) form a group: their multipliers are
/// solved together. E is the group's incidence (chambers x walls: +1 where the chamber grows with
/// the wall's constrained volume, -1 where it shrinks, 0 where the wall is not its), W or C the
/// walls' weights (compliances dV/dlambda). Two operations follow:
/// - a volume change d of the chambers is split into the walls' shares of least W^-1-weighted
///   size: s = W E^T (E W E^T)^-1 d, so that E s = d;
/// - walls that returned multipliers lambda agree best with the chambers' multipliers Lambda of
///   E C E^T Lambda = E C lambda (each wall then carries (E^T Lambda)_i).
/// With one chamber (E a row of ones) these are the weight-proportional split and the
/// compliance-weighted mean.
#include <Eigen/Dense>

#include <utility>
#include <vector>

namespace mfsi::coupling {

/// Chambers joined by shared walls, and their walls.
struct ChamberGroup {
  std::vector<int> chambers;  ///< chamber indices, ascending
  std::vector<int> panels;    ///< every wall's panel once, in the order the grouping met them
  Eigen::MatrixXd incidence;  ///< chambers x panels: each wall's sign in each chamber, 0 where it is none

  /// The column of `panel` in `panels` (-1 when it is not a wall of the group).
  Eigen::Index column(int panel) const;
  /// Some wall leads out of every subset of the chambers (E has full row rank): else their
  /// inflows would have to cancel, and only differences of their pressures would be fixed.
  bool pressuresFixed() const;
};

/// Groups chambers by shared walls. `walls[k]`: chamber k's walls as (panel, sign). Groups come in
/// the order of their first chamber; each group's panels in the order a flood from that chamber
/// meets them.
std::vector<ChamberGroup> groupChambers(const std::vector<std::vector<std::pair<int, double>>>& walls);

/// The walls' volume changes of least `weight`^-1-weighted size that change the group's chambers'
/// volumes by d: W E^T (E W E^T)^-1 d.
Eigen::VectorXd shareOut(const ChamberGroup& g, const Eigen::VectorXd& weight, const Eigen::VectorXd& d);

/// The chambers' multipliers that the walls' multipliers `lambda` agree with best, weighted by the
/// walls' compliances C: the solution of E C E^T Lambda = E C lambda.
Eigen::VectorXd agreedMultipliers(const ChamberGroup& g, const Eigen::VectorXd& C, const Eigen::VectorXd& lambda);

}  // namespace mfsi::coupling
