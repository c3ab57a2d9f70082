#pragma once
/// \file
/// \brief A closed chamber of the coupling: the membranes (walls) and bodies that bound it, and
/// the volume bookkeeping of its constraint.
///
/// A closed fluid region (or the whole closed domain, or a lumped gas chamber behind a membrane)
/// dictates its walls' swept volume: the walls solve with a volume constraint whose multiplier is
/// the chamber's uniform pressure (MembraneVolumeConstraint). A chamber bounded by several
/// membranes carries one multiplier on all of them: each membrane solves with a share of the
/// chamber's volume target as its own, and the shares move until the multipliers agree
/// (ChamberGroup). The orchestrator (FsiCoupling) owns the chambers and runs them.
#include "core/Types.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <vector>

namespace mfsi::coupling {

/// The walls of a chamber's group agree on its multiplier when theirs differ by at most this
/// times fsiTol times the pressure they carry (the largest multiplier or element load), so that
/// what is left of the disagreement stays far below what the coupling's convergence test sees.
inline constexpr double kShareAgreement = 1e-3;
/// ... and the shares (or the bodies' multiplier) move at most this many times in one structure solve.
inline constexpr int kMaxShareRounds = 30;

/// A membrane that bounds a chamber.
struct ChamberWall {
  int panel = -1;  ///< the coupling's panel (membrane) index
  /// +1: the chamber grows with its membrane's constrained volume (the chamber the membrane's
  /// MembraneVolumeConstraint::sign was set for); -1: a membrane between two closed chambers, seen
  /// from the second one, which it shrinks.
  real sign = 1;
  double volumeStart = 0;  ///< its share of the chamber's volume change at the step's start (frame-relative; x sign)
  int parent = -1;         ///< mounted: the coupled-body slot of its one parent body
  bool blended = false;    ///< mounted on several bodies, each node blended between them (ParentFrames)
  RealView rigid;          ///< mounted: its nodes' displacement were they carried rigidly by the body
  RealView relative;       ///< blended: its frame-relative displacement (the rigid volume's work space)
  RealView pressure;       ///< mounted: its multiplier on every element (what its body receives of it)
};

/// A coupled body's faces that bound a chamber: as the body moves they change its volume, and the
/// chamber's pressure pushes on them.
struct ChamberBody {
  int slot = -1;                              ///< the coupled-body slot
  std::vector<std::array<double, 12>> faces;  ///< this rank's (owned) faces: reference corners
  Eigen::Vector3d area = Eigen::Vector3d::Zero();    ///< sum of their area vectors out of the fluid (all ranks)
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< sum of (centroid - start centre of mass) x area (all ranks)
};

/// One closed chamber and its bookkeeping.
struct Chamber {
  std::vector<ChamberWall> walls;
  std::vector<ChamberBody> bodies;  ///< bodies that bound it (the parents of mounted walls among them)
  int fluidRegion = -1;  ///< the fluid's closed region (FluidSolver::addClosedRegion); -1: the whole domain
  bool lumped = false;   ///< an unmeshed gas chamber behind the membrane (coupling.lumpedChamber)
  int group = -1;        ///< its ChamberGroup (the chambers it shares walls with)
  double volumeStart = 0;  ///< the chamber's volume change where the fluid mesh is at the step's start
  /// Moving walls (bodies, mounted membranes): the volume change the bodies' rigid motion makes
  /// (mounted membranes carried undeformed), at the step's start and for the walls' current
  /// targets. The walls' frame-relative volumes make up the rest.
  double rigidStart = 0, rigidNow = 0;
  double sweptLast = 0;   ///< what the membranes swept in the last step (the BDF2 mesh flux reads it)
  double maxMissRun = 0;  ///< largest volume miss of the run [m^3]
  int maxRoundsRun = 0;   ///< most share rounds of one structure solve in the run
  int maxSweepsRun = 0;   ///< most bodies' multiplier sweeps of one structure solve in the run
  // This step's:
  double volumeStep = 0;  ///< the target's change over the step [m^3]
  double volumeMiss = 0;  ///< largest |volume change - target| of its iterates [m^3]
  double pressure = 0;    ///< the chamber's pressure [Pa]
  double lambda = 0;      ///< the multiplier of the last structure solve (several walls: their agreed one)
  /// Moving walls: the multiplier the bodies were last solved with (the structure solve iterates
  /// it by secant until the walls' multiplier returns it) and its value at the step's start.
  double bodyLambda = 0, bodyLambdaStart = 0;
  double spread = 0;  ///< several walls: max |lambda_i - lambda| / the pressure scale, last solve
  int rounds = 0;     ///< several walls: most share rounds of one structure solve this step
  int sweeps = 0;     ///< moving walls: most multiplier sweeps of one structure solve this step

  /// Bodies bound it or carry one of its walls.
  bool moving() const {
    return !bodies.empty() ||
           std::any_of(walls.begin(), walls.end(), [](const ChamberWall& w) { return w.parent >= 0 || w.blended; });
  }
  /// A wall is blended between bodies.
  bool blended() const {
    return std::any_of(walls.begin(), walls.end(), [](const ChamberWall& w) { return w.blended; });
  }
};

}  // namespace mfsi::coupling
