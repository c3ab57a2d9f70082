#pragma once
/// \file
/// \brief Rigid multi-body frame dynamics: a `RigidBodyModel` tree with gravity, restraints,
/// prescribed rotations and external (fluid) loads, advanced in time by an implicit Newmark scheme
/// with OpenFOAM rigidBodyMotion's accelerationRelaxation and accelerationDamping.
///
/// Time stepping, as in OpenFOAM (motionState0 / motionState):
///   - `step(t, dt)` advances from t (= time()) to t + dt and commits: `solveStep` + `commitStep`.
///   - For implicit FSI coupling, call `setExternalLoad` + `solveStep(t, dt)` once per coupling
///     iteration (each call restarts from the committed state with the latest loads and relaxes
///     against the previous iterate), then `commitStep()` once the coupling has converged.
///
/// Newmark with accelerations a = qddot (d = accelerationDamping):
///   q1    = q0 + dt qdot0 + d dt^2 ((1/2 - beta) a0 + beta a1)
///   qdot1 = qdot0 + d dt ((1 - gamma) a0 + gamma a1)
///   M(q1) a1 = Q(t1, q1, qdot1)      solved for a1 by Newton (FD Jacobian) or fixed point,
/// then a1 <- r a1 + (1 - r) a_prev (r = accelerationRelaxation) and q1, qdot1 are recomputed.
#include "core/io/Checkpoint.hpp"
#include "structure/rigid/RigidBodyModel.hpp"
#include "structure/rigid/RigidOptions.hpp"
#include "structure/rigid/RigidRestraint.hpp"

#include <Eigen/Dense>

#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace mfsi {

/// \brief Everything reported per body and step (world axes, CoM-based).
struct RigidBodyReport {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();         ///< centre of mass
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();  ///< body -> world rotation
  /// (roll, pitch, yaw) with orientation = Rz(yaw) Ry(pitch) Rx(roll).
  Eigen::Vector3d eulerAngles = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();         ///< CoM velocity
  Eigen::Vector3d angularVelocity = Eigen::Vector3d::Zero();  ///< omega
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();     ///< CoM acceleration
  Eigen::Vector3d angularAcceleration = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< total applied force (gravity, restraints, external)
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< total applied moment about the CoM
};

/// \brief (roll, pitch, yaw) of a rotation matrix R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d rigidEulerAngles(const Eigen::Matrix3d& R);

/// \brief A rigid multi-body system with state, loads and a Newmark time integrator.
class RigidBodySystem {
 public:
  /// \brief Build the tree, restraints and solver; the state starts from the joints' q0/qdot0
  /// at options.startTime. Throws InputError on invalid options.
  explicit RigidBodySystem(const RigidSystemOptions& options);

  // --- time stepping ------------------------------------------------------------------------
  /// \brief Advance from t (must equal time()) to t + dt and commit the new state.
  void step(double t, double dt);
  /// \brief Compute the state at t + dt from the committed state at t (= time()) with the current
  /// loads, without committing. May be called repeatedly (coupling iterations). Throws
  /// DivergenceError if the nonlinear iteration does not converge or the state turns non-finite.
  void solveStep(double t, double dt);
  /// \brief Accept the state of the last `solveStep` as the start of the next step.
  void commitStep();
  /// \brief Time of the committed state.
  double time() const { return state0_.t; }
  /// \brief Committed steps so far.
  long steps() const { return steps_; }
  /// \brief Iterations of the last solveStep's nonlinear solve.
  int lastIterations() const { return lastIterations_; }

  // --- loads ----------------------------------------------------------------------------------
  /// \brief External load on a body: `force` applied at the world point `point` (taken at the
  /// current configuration and then carried with the body) plus a pure couple `moment`.
  /// Replaces the previous external load of that body. World axes.
  void setExternalLoad(int body, const Eigen::Vector3d& force, const Eigen::Vector3d& moment,
                       const Eigen::Vector3d& point);
  /// \brief External load with the force applied at the body's centre of mass.
  void setExternalLoad(int body, const Eigen::Vector3d& force, const Eigen::Vector3d& moment);
  /// \brief Remove all external loads.
  void clearExternalLoads();
  /// \brief Extra generalised forces tau (one per free coordinate; N or N m), e.g. joint motors.
  void setGeneralisedForce(const Eigen::VectorXd& tau);

  // --- state ----------------------------------------------------------------------------------
  /// \brief Overwrite the committed coordinates and rates (accelerations are recomputed).
  void setState(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot);
  /// \brief Latest coordinates (the committed state, or the last solveStep's result before commit).
  const Eigen::VectorXd& q() const { return state_.q; }
  /// \brief Latest generalised rates.
  const Eigen::VectorXd& qdot() const { return state_.qdot; }
  /// \brief Latest generalised accelerations.
  const Eigen::VectorXd& qddot() const { return state_.qddot; }
  /// \brief Number of free generalised coordinates (including prescribedRotation ones).
  int nDof() const { return model_.nDof(); }
  /// \brief Number of bodies.
  int nBodies() const { return model_.nBodies(); }
  /// \brief Index of a body by name (throws InputError if unknown).
  int bodyIndex(const std::string& name) const { return model_.bodyIndex(name); }
  /// \brief Point masses at world positions (the current pose) join body b (RigidBodyModel::
  /// addPointMasses); before the first step.
  void addPointMasses(int b, const std::vector<double>& m, const std::vector<Eigen::Vector3d>& worldPositions);
  /// \brief The kinematic tree.
  const RigidBodyModel& model() const { return model_; }
  /// \brief The options the system was built from.
  const RigidSystemOptions& options() const { return options_; }
  /// \brief World pose, velocities, accelerations and loads of body b (latest state).
  RigidBodyReport bodyReport(int b) const;
  /// \brief Kinematics of all bodies at the latest state.
  const RigidTreeKinematics& kinematics() const { return kin_; }
  /// \brief Joint-space mass matrix at the latest state.
  Eigen::MatrixXd massMatrix() const;

  // --- checkpoints ---------------------------------------------------------------------------
  /// \brief Write everything a later step and the reports read, so a system built from the same
  /// options continues bitwise after `loadState`: the committed and the latest state (t, q, qdot,
  /// qddot; the latest one is the start iterate of the next solve), whether a solve awaits its
  /// commit or a0 must be recomputed, external loads and generalised forces, the reported body
  /// loads and motor torques, the start pose, the running maxima and the iteration counters. The
  /// restraints and the model hold no state; the kinematics are recomputed from the latest state.
  void saveState(io::StateWriter& w) const;
  /// \brief Read what `saveState` wrote. Throws InputError naming the checkpoint and dataset when it
  /// does not fit (another number of bodies, coordinates or prescribed rotations).
  void loadState(const io::StateReader& r);

  // --- energies and summary -------------------------------------------------------------------
  /// \brief sum 1/2 m v_CoM^2 + 1/2 omega . I omega (includes prescribed motion).
  double kineticEnergy() const;
  /// \brief Gravity (-sum m g . x_CoM) plus spring energy.
  double potentialEnergy() const;
  /// \brief Summary values of the latest state:
  ///  - "time", "steps", "kineticEnergy", "potentialEnergy", "totalEnergy", "maxDisplacement" (all bodies),
  ///    "solver.iterations" (last solve), "solver.maxIterations" (whole run);
  ///  - per body "body.<name>.": x y z (CoM), vx vy vz, ax ay az, wx wy wz, Fx Fy Fz, Mx My Mz, roll pitch
  ///    yaw, displacement and rotation (from the start), maxDisplacement and maxRotation (over committed
  ///    steps), q<k> and qdot<k> per free joint axis k;
  ///  - per spring "restraint.<name>.length" / ".force" (tension); per prescribed rotation
  ///    "restraint.<name>.torque" (motor torque), ".angle", ".error" (angle - function).
  std::map<std::string, double> metrics() const;

  /// \brief Write the CSV header matching `writeCsvRows`.
  static void writeCsvHeader(std::ostream& os);
  /// \brief One CSV line per body for the latest state.
  void writeCsvRows(std::ostream& os) const;

 private:
  struct State {
    double t = 0;
    Eigen::VectorXd q, qdot, qddot;
  };
  struct Constraint {
    std::string name;
    int dof = -1;
    RigidTimeFunction angle;
    double frequency = 0;
    double dampingRatio = 1;
  };
  struct ExternalLoad {
    bool active = false;
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    Eigen::Vector3d localPoint = Eigen::Vector3d::Zero();  ///< body frame
  };

  /// Loads on every body for the kinematics (gravity, restraints, external).
  void bodyLoads(const RigidTreeKinematics& kin, std::vector<RigidBodyLoad>& loads) const;
  /// M and Q at (t, q, qdot); fills the bias kinematics and the loads.
  void evaluate(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Eigen::MatrixXd& M, Eigen::VectorXd& Q,
                RigidTreeKinematics& biasKin, std::vector<RigidBodyLoad>& loads) const;
  /// Free accelerations solving M_FF aF = Q_F - M_FC aC.
  Eigen::VectorXd solveFree(const Eigen::MatrixXd& M, const Eigen::VectorXd& Q, const Eigen::VectorXd& aC) const;
  /// Consistent accelerations of the committed state (start of the run or after setState).
  void initialiseAcceleration();
  /// Recompute kinematics, loads and constraint torques of state_.
  void refreshLatest();

  RigidSystemOptions options_;
  RigidBodyModel model_;
  RigidRestraints restraints_;
  std::vector<Constraint> constraints_;
  std::vector<int> freeDofs_;
  std::vector<int> constrainedDofs_;
  std::vector<ExternalLoad> external_;
  Eigen::VectorXd tau_;

  State state0_;  ///< committed state (start of the current step)
  State state_;   ///< latest state (= state0_ after a commit)
  bool accelerationStale_ = true;
  RigidTreeKinematics kin_;           ///< kinematics of state_ with its accelerations
  std::vector<RigidBodyLoad> loads_;  ///< loads at state_
  Eigen::VectorXd constraintTorque_;  ///< motor torque per constraint at state_
  std::vector<Eigen::Vector3d> initialCom_;
  std::vector<Eigen::Matrix3d> initialRotation_;
  std::vector<double> maxDisplacement_;
  std::vector<double> maxRotation_;
  long steps_ = 0;
  bool pending_ = false;       ///< a solveStep result awaits commitStep
  bool lastConverged_ = true;  ///< last solveStep's nonlinear iteration converged
  int lastIterations_ = 0;
  int maxIterationsUsed_ = 0;
};

}  // namespace mfsi
