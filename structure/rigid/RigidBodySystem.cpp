#include "structure/rigid/RigidBodySystem.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>

namespace mfsi {

Eigen::Vector3d rigidEulerAngles(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

namespace {
/// Rotation angle of R in [0, pi].
double rotationAngle(const Eigen::Matrix3d& R) { return std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0)); }

std::vector<double> flat(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }
Eigen::VectorXd vectorOf(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}
void append(std::vector<double>& to, const Eigen::Vector3d& v) { to.insert(to.end(), {v[0], v[1], v[2]}); }
/// The i-th triple of a flat list of 3-vectors.
Eigen::Vector3d vector3At(const std::vector<double>& v, std::size_t i) {
  return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}
}  // namespace

RigidBodySystem::RigidBodySystem(const RigidSystemOptions& options)
    : options_(options), model_(options.bodies), restraints_(model_, options) {
  const RigidNewmarkOptions& s = options_.solver;
  MFSI_CHECK(s.gamma >= 0 && s.gamma <= 1, "rigid solver: gamma must lie in [0, 1], got " << s.gamma);
  MFSI_CHECK(s.beta >= 0 && s.beta <= 0.5, "rigid solver: beta must lie in [0, 0.5], got " << s.beta);
  MFSI_CHECK(s.accelerationRelaxation > 0 && s.accelerationRelaxation <= 1,
             "rigid solver: accelerationRelaxation must lie in (0, 1], got " << s.accelerationRelaxation);
  MFSI_CHECK(s.accelerationDamping >= 0 && s.accelerationDamping <= 1,
             "rigid solver: accelerationDamping must lie in [0, 1], got " << s.accelerationDamping);
  MFSI_CHECK(s.maxIterations >= 1, "rigid solver: maxIterations must be >= 1");
  MFSI_CHECK(s.tolerance > 0, "rigid solver: tolerance must be positive");
  MFSI_CHECK(options_.gravity.allFinite(), "rigid system: gravity must be finite");

  std::vector<bool> constrained(model_.nDof(), false);
  for (const auto& p : options_.prescribedRotations) {
    const std::string where = "rigid prescribedRotation '" + p.name + "'";
    const int b = model_.bodyIndex(p.body);
    const auto& axes = model_.jointAxes(b);
    int k = p.axis;
    if (k < 0) {
      const auto it = std::find_if(axes.begin(), axes.end(), [](RigidAxis a) { return isRevolute(a); });
      MFSI_CHECK(it != axes.end(), where << ": body '" << p.body << "' has no revolute joint axis");
      k = static_cast<int>(it - axes.begin());
    }
    MFSI_CHECK(k < static_cast<int>(axes.size()) && isRevolute(axes[k]),
               where << ": axis " << k << " of body '" << p.body << "' is not a revolute axis");
    const int dof = model_.axisDof(b, k);
    MFSI_CHECK(dof >= 0, where << ": body '" << p.body << "' has a prescribed joint already");
    MFSI_CHECK(!constrained[dof], where << ": that coordinate is already prescribed");
    MFSI_CHECK(p.angle.valid(), where << ": angle function is empty");
    MFSI_CHECK(p.dampingRatio >= 0, where << ": dampingRatio must be non-negative");
    constrained[dof] = true;
    constraints_.push_back({p.name, dof, p.angle, p.frequency, p.dampingRatio});
  }
  for (int i = 0; i < model_.nDof(); ++i) (constrained[i] ? constrainedDofs_ : freeDofs_).push_back(i);

  external_.resize(model_.nBodies());
  tau_.setZero(model_.nDof());
  state0_.t = options_.startTime;
  model_.initialState(state0_.q, state0_.qdot);
  // A prescribed coordinate starts on its function, whatever q0 says.
  for (const auto& c : constraints_) {
    state0_.q[c.dof] = c.angle(state0_.t);
    state0_.qdot[c.dof] = c.angle.derivative(state0_.t);
  }
  state0_.qddot.setZero(model_.nDof());
  initialiseAcceleration();

  initialCom_.resize(model_.nBodies());
  initialRotation_.resize(model_.nBodies());
  for (int b = 0; b < model_.nBodies(); ++b) {
    initialCom_[b] = kin_.bodies[b].com;
    initialRotation_[b] = kin_.bodies[b].frame.rotation;
  }
  maxDisplacement_.assign(model_.nBodies(), 0.0);
  maxRotation_.assign(model_.nBodies(), 0.0);
  // Loads may still be set before the first step: recompute a0 then.
  accelerationStale_ = true;
}

void RigidBodySystem::addPointMasses(int b, const std::vector<double>& m, const std::vector<Eigen::Vector3d>& x) {
  const RigidFrameMotion& f = kin_.bodies[b].frame;
  std::vector<Eigen::Vector3d> local(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) local[i] = f.rotation.transpose() * (x[i] - f.origin);
  model_.addPointMasses(b, m, local);
  model_.kinematics(state_.t, state_.q, state_.qdot, state_.qddot, kin_);
  initialCom_[b] = kin_.bodies[b].com;
  accelerationStale_ = true;
}

// --- loads and equations ----------------------------------------------------------------------

void RigidBodySystem::bodyLoads(const RigidTreeKinematics& kin, std::vector<RigidBodyLoad>& loads) const {
  loads.assign(model_.nBodies(), RigidBodyLoad{});
  for (int b = 0; b < model_.nBodies(); ++b) {
    loads[b].force += model_.mass(b) * options_.gravity;
    const ExternalLoad& e = external_[b];
    if (!e.active) continue;
    const RigidFrameMotion& f = kin.bodies[b].frame;
    const Eigen::Vector3d p = f.origin + f.rotation * e.localPoint;
    loads[b].force += e.force;
    loads[b].moment += e.moment + (p - kin.bodies[b].com).cross(e.force);
  }
  restraints_.addLoads(kin, loads);
}

void RigidBodySystem::evaluate(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Eigen::MatrixXd& M,
                               Eigen::VectorXd& Q, RigidTreeKinematics& biasKin,
                               std::vector<RigidBodyLoad>& loads) const {
  model_.kinematics(t, q, qdot, Eigen::VectorXd::Zero(model_.nDof()), biasKin);
  bodyLoads(biasKin, loads);
  model_.equations(biasKin, loads, M, Q);
  Q += tau_;
}

Eigen::VectorXd RigidBodySystem::solveFree(const Eigen::MatrixXd& M, const Eigen::VectorXd& Q,
                                           const Eigen::VectorXd& aC) const {
  const int nF = static_cast<int>(freeDofs_.size());
  const int nC = static_cast<int>(constrainedDofs_.size());
  Eigen::MatrixXd MFF(nF, nF);
  Eigen::VectorXd rhs(nF);
  for (int i = 0; i < nF; ++i) {
    rhs[i] = Q[freeDofs_[i]];
    for (int j = 0; j < nC; ++j) rhs[i] -= M(freeDofs_[i], constrainedDofs_[j]) * aC[j];
    for (int j = 0; j < nF; ++j) MFF(i, j) = M(freeDofs_[i], freeDofs_[j]);
  }
  Eigen::LLT<Eigen::MatrixXd> llt(MFF);
  MFSI_CHECK(llt.info() == Eigen::Success,
             "rigid system: singular mass matrix (a free coordinate moves no mass or inertia)");
  return llt.solve(rhs);
}

void RigidBodySystem::initialiseAcceleration() {
  Eigen::MatrixXd M;
  Eigen::VectorXd Q;
  RigidTreeKinematics kin;
  std::vector<RigidBodyLoad> loads;
  evaluate(state0_.t, state0_.q, state0_.qdot, M, Q, kin, loads);
  Eigen::VectorXd aC(constraints_.size());
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    const Constraint& k = constraints_[c];
    const double w = std::max(k.frequency, 0.0);
    const double t = state0_.t;
    aC[c] = k.angle.secondDerivative(t) + 2 * k.dampingRatio * w * (k.angle.derivative(t) - state0_.qdot[k.dof]) +
            w * w * (k.angle(t) - state0_.q[k.dof]);
  }
  const Eigen::VectorXd aF = solveFree(M, Q, aC);
  for (std::size_t i = 0; i < freeDofs_.size(); ++i) state0_.qddot[freeDofs_[i]] = aF[i];
  for (std::size_t c = 0; c < constrainedDofs_.size(); ++c) state0_.qddot[constrainedDofs_[c]] = aC[c];
  state_ = state0_;
  pending_ = false;
  refreshLatest();
  accelerationStale_ = false;
}

void RigidBodySystem::refreshLatest() {
  Eigen::MatrixXd M;
  Eigen::VectorXd Q;
  RigidTreeKinematics biasKin;
  evaluate(state_.t, state_.q, state_.qdot, M, Q, biasKin, loads_);
  model_.kinematics(state_.t, state_.q, state_.qdot, state_.qddot, kin_);
  // The motor torque of a prescribed coordinate is whatever closes its row of M qddot = Q + tau.
  constraintTorque_.setZero(constraints_.size());
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    const int d = constraints_[c].dof;
    constraintTorque_[c] = M.row(d).dot(state_.qddot) - Q[d];
  }
}

// --- time stepping ------------------------------------------------------------------------------

void RigidBodySystem::step(double t, double dt) {
  solveStep(t, dt);
  commitStep();
}

void RigidBodySystem::solveStep(double t, double dt) {
  MFSI_CHECK(dt > 0 && std::isfinite(dt), "rigid system: time step must be positive, got " << dt);
  MFSI_CHECK(std::abs(t - state0_.t) <= 1e-9 * std::max(1.0, std::abs(t)) + 1e-6 * dt,
             "rigid system: step starts at t = " << t << " but the committed state is at t = " << state0_.t);
  if (accelerationStale_) initialiseAcceleration();

  const RigidNewmarkOptions& opt = options_.solver;
  const int n = model_.nDof();
  const int nF = static_cast<int>(freeDofs_.size());
  const double beta = opt.beta, gamma = opt.gamma;
  const double t1 = t + dt;
  const State& s0 = state0_;

  // Per-coordinate acceleration damping; prescribed coordinates must follow their function.
  Eigen::VectorXd damp = Eigen::VectorXd::Constant(n, opt.accelerationDamping);
  for (int d : constrainedDofs_) damp[d] = 1.0;
  // Newmark predictor: everything that does not depend on the new acceleration.
  const Eigen::VectorXd qStar = s0.q + dt * s0.qdot + dt * dt * (0.5 - beta) * damp.cwiseProduct(s0.qddot);
  const Eigen::VectorXd qdStar = s0.qdot + dt * (1.0 - gamma) * damp.cwiseProduct(s0.qddot);
  const Eigen::VectorXd qCoef = beta * dt * dt * damp;
  const Eigen::VectorXd qdCoef = gamma * dt * damp;

  // Prescribed coordinates: qddot = f'' + 2 zeta w (f' - qdot1) + w^2 (f - q1) with q1, qdot1 linear in
  // qddot, solved in closed form. The error then follows a damped oscillator integrated by the same
  // (A-stable for gamma >= 1/2, 2 beta >= gamma) Newmark scheme, so any w is stable.
  Eigen::VectorXd aC(constraints_.size());
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    const Constraint& k = constraints_[c];
    const int d = k.dof;
    const double w = k.frequency > 0 ? k.frequency : 0.25 / dt;
    const double z = k.dampingRatio;
    const double num = k.angle.secondDerivative(t1) + 2 * z * w * (k.angle.derivative(t1) - qdStar[d]) +
                       w * w * (k.angle(t1) - qStar[d]);
    aC[c] = num / (1.0 + 2 * z * w * qdCoef[d] + w * w * qCoef[d]);
  }

  Eigen::VectorXd a(n), q1(n), qd1(n);
  for (std::size_t c = 0; c < constrainedDofs_.size(); ++c) a[constrainedDofs_[c]] = aC[c];
  Eigen::MatrixXd M;
  Eigen::VectorXd Q;
  RigidTreeKinematics kin;
  std::vector<RigidBodyLoad> loads;
  // g(aF): the free accelerations the equations of motion give at the Newmark state built from aF.
  auto g = [&](const Eigen::VectorXd& aF) {
    for (int i = 0; i < nF; ++i) a[freeDofs_[i]] = aF[i];
    q1 = qStar + qCoef.cwiseProduct(a);
    qd1 = qdStar + qdCoef.cwiseProduct(a);
    evaluate(t1, q1, qd1, M, Q, kin, loads);
    return solveFree(M, Q, aC);
  };

  // Start from the previous iterate (previous coupling iteration, or a0 on the first call).
  Eigen::VectorXd aPrev(nF), aF(nF);
  for (int i = 0; i < nF; ++i) aPrev[i] = state_.qddot[freeDofs_[i]];
  aF = aPrev;
  lastConverged_ = false;
  lastIterations_ = 0;
  for (int it = 0; it < opt.maxIterations; ++it) {
    const Eigen::VectorXd g0 = g(aF);
    ++lastIterations_;
    if (!g0.allFinite()) throw DivergenceError("rigid system: non-finite acceleration at t = " + std::to_string(t1));
    const Eigen::VectorXd r = aF - g0;
    const double scale = 1.0 + (nF > 0 ? g0.lpNorm<Eigen::Infinity>() : 0.0);
    if (nF == 0 || r.lpNorm<Eigen::Infinity>() <= opt.tolerance * scale) {
      aF = g0;
      lastConverged_ = true;
      break;
    }
    if (opt.iteration == RigidIteration::FixedPoint) {
      aF = g0;
      continue;
    }
    // Newton on r(aF) = aF - g(aF) with a forward-difference Jacobian: n is a handful of coordinates,
    // so n extra evaluations are cheaper than deriving dQ/dq for every restraint and joint type.
    Eigen::MatrixXd J = Eigen::MatrixXd::Identity(nF, nF);
    for (int j = 0; j < nF; ++j) {
      Eigen::VectorXd ap = aF;
      const double h = 1e-6 * (1.0 + std::abs(aF[j]));
      ap[j] += h;
      J.col(j) -= (g(ap) - g0) / h;
    }
    aF -= J.partialPivLu().solve(r);
  }
  maxIterationsUsed_ = std::max(maxIterationsUsed_, lastIterations_);
  if (!lastConverged_) {
    // A half-solved step would silently violate the equations of motion: fail loudly instead.
    throw DivergenceError("rigid system: Newmark iteration did not converge in " + std::to_string(opt.maxIterations) +
                          " iterations at t = " + std::to_string(t1) +
                          " (use iteration Newton, a smaller time step or more iterations)");
  }

  const double relax = opt.accelerationRelaxation;
  aF = relax * aF + (1.0 - relax) * aPrev;
  for (int i = 0; i < nF; ++i) a[freeDofs_[i]] = aF[i];
  state_.t = t1;
  state_.qddot = a;
  state_.q = qStar + qCoef.cwiseProduct(a);
  state_.qdot = qdStar + qdCoef.cwiseProduct(a);
  if (!state_.q.allFinite() || !state_.qdot.allFinite()) {
    throw DivergenceError("rigid system: non-finite state at t = " + std::to_string(t1));
  }
  refreshLatest();
  pending_ = true;
}

void RigidBodySystem::commitStep() {
  MFSI_CHECK(pending_, "rigid system: commitStep() without a preceding solveStep()");
  state0_ = state_;
  pending_ = false;
  ++steps_;
  for (int b = 0; b < model_.nBodies(); ++b) {
    maxDisplacement_[b] = std::max(maxDisplacement_[b], (kin_.bodies[b].com - initialCom_[b]).norm());
    maxRotation_[b] =
        std::max(maxRotation_[b], rotationAngle(kin_.bodies[b].frame.rotation * initialRotation_[b].transpose()));
  }
}

// --- loads and state setters ------------------------------------------------------------------

void RigidBodySystem::setExternalLoad(int body, const Eigen::Vector3d& force, const Eigen::Vector3d& moment,
                                      const Eigen::Vector3d& point) {
  MFSI_CHECK(body >= 0 && body < model_.nBodies(), "rigid system: no body with index " << body);
  MFSI_CHECK(force.allFinite() && moment.allFinite() && point.allFinite(),
             "rigid system: non-finite external load on body '" << model_.bodyName(body) << "'");
  const RigidFrameMotion& f = kin_.bodies[body].frame;
  ExternalLoad& e = external_[body];
  e.active = true;
  e.force = force;
  e.moment = moment;
  e.localPoint = f.rotation.transpose() * (point - f.origin);
}

void RigidBodySystem::setExternalLoad(int body, const Eigen::Vector3d& force, const Eigen::Vector3d& moment) {
  MFSI_CHECK(body >= 0 && body < model_.nBodies(), "rigid system: no body with index " << body);
  setExternalLoad(body, force, moment, kin_.bodies[body].com);
}

void RigidBodySystem::clearExternalLoads() { external_.assign(model_.nBodies(), ExternalLoad{}); }

void RigidBodySystem::setGeneralisedForce(const Eigen::VectorXd& tau) {
  MFSI_CHECK(tau.size() == model_.nDof(),
             "rigid system: generalised force needs " << model_.nDof() << " values, got " << tau.size());
  tau_ = tau;
}

void RigidBodySystem::setState(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) {
  MFSI_CHECK(q.size() == model_.nDof() && qdot.size() == model_.nDof(),
             "rigid system: setState needs " << model_.nDof() << " coordinates and rates");
  state0_.q = q;
  state0_.qdot = qdot;
  initialiseAcceleration();
  accelerationStale_ = true;
}

// --- checkpoints --------------------------------------------------------------------------------

void RigidBodySystem::saveState(io::StateWriter& w) const {
  auto putState = [](io::StateWriter sw, const State& st) {
    sw.putReal("t", st.t);
    sw.put("q", flat(st.q));
    sw.put("qdot", flat(st.qdot));
    sw.put("qddot", flat(st.qddot));
  };
  putState(w.sub("committed"), state0_);
  putState(w.sub("latest"), state_);
  w.putBool("pending", pending_);
  w.putBool("accelerationStale", accelerationStale_);
  w.putInt("steps", steps_);
  w.putBool("lastConverged", lastConverged_);
  w.putInt("lastIterations", lastIterations_);
  w.putInt("maxIterationsUsed", maxIterationsUsed_);
  w.put("generalisedForce", flat(tau_));
  // Per body, 3 values each (body-major).
  std::vector<std::int64_t> active;
  std::vector<double> force, moment, point, loadForce, loadMoment, com, rotation;
  for (int b = 0; b < model_.nBodies(); ++b) {
    const ExternalLoad& e = external_[b];
    active.push_back(e.active ? 1 : 0);
    append(force, e.force);
    append(moment, e.moment);
    append(point, e.localPoint);
    append(loadForce, loads_[b].force);
    append(loadMoment, loads_[b].moment);
    append(com, initialCom_[b]);
    for (int i = 0; i < 3; ++i) append(rotation, initialRotation_[b].row(i).transpose());
  }
  io::StateWriter ext = w.sub("external");
  ext.put("active", active);
  ext.put("force", force);
  ext.put("moment", moment);
  ext.put("localPoint", point);
  io::StateWriter reported = w.sub("reported");
  reported.put("force", loadForce);
  reported.put("moment", loadMoment);
  reported.put("constraintTorque", flat(constraintTorque_));
  w.put("initialCom", com);
  w.put("initialRotation", rotation);
  w.put("maxDisplacement", maxDisplacement_);
  w.put("maxRotation", maxRotation_);
}

void RigidBodySystem::loadState(const io::StateReader& r) {
  // Everything is read (and checked) before anything changes.
  const int n = model_.nDof();
  const std::size_t nB = static_cast<std::size_t>(model_.nBodies());
  const long long n3 = 3 * static_cast<long long>(nB);
  auto getState = [n](const io::StateReader& sr) {
    State st;
    st.t = sr.real("t");
    st.q = vectorOf(sr.doubles("q", n));
    st.qdot = vectorOf(sr.doubles("qdot", n));
    st.qddot = vectorOf(sr.doubles("qddot", n));
    return st;
  };
  const State committed = getState(r.sub("committed")), latest = getState(r.sub("latest"));
  const Eigen::VectorXd tau = vectorOf(r.doubles("generalisedForce", n));
  const io::StateReader ext = r.sub("external"), reported = r.sub("reported");
  const std::vector<std::int64_t> active = ext.ints("active", static_cast<long long>(nB));
  const std::vector<double> force = ext.doubles("force", n3), moment = ext.doubles("moment", n3),
                            point = ext.doubles("localPoint", n3), loadForce = reported.doubles("force", n3),
                            loadMoment = reported.doubles("moment", n3),
                            torque = reported.doubles("constraintTorque", static_cast<long long>(constraints_.size())),
                            com = r.doubles("initialCom", n3), rotation = r.doubles("initialRotation", 3 * n3),
                            maxDisplacement = r.doubles("maxDisplacement", static_cast<long long>(nB)),
                            maxRotation = r.doubles("maxRotation", static_cast<long long>(nB));
  const bool pending = r.boolean("pending"), stale = r.boolean("accelerationStale"),
             converged = r.boolean("lastConverged");
  const long long steps = r.integer("steps"), lastIterations = r.integer("lastIterations"),
                  maxIterations = r.integer("maxIterationsUsed");

  state0_ = committed;
  state_ = latest;
  tau_ = tau;
  for (std::size_t b = 0; b < nB; ++b) {
    ExternalLoad& e = external_[b];
    e.active = active[b] != 0;
    e.force = vector3At(force, b);
    e.moment = vector3At(moment, b);
    e.localPoint = vector3At(point, b);
    loads_[b].force = vector3At(loadForce, b);
    loads_[b].moment = vector3At(loadMoment, b);
    initialCom_[b] = vector3At(com, b);
    for (int i = 0; i < 3; ++i) initialRotation_[b].row(i) = vector3At(rotation, 3 * b + i).transpose();
  }
  constraintTorque_ = vectorOf(torque);
  maxDisplacement_ = maxDisplacement;
  maxRotation_ = maxRotation;
  pending_ = pending;
  accelerationStale_ = stale;
  lastConverged_ = converged;
  steps_ = static_cast<long>(steps);
  lastIterations_ = static_cast<int>(lastIterations);
  maxIterationsUsed_ = static_cast<int>(maxIterations);
  // The kinematics are a function of the latest state alone; the reported loads are not (they are
  // those of the solve, while the external loads may have been replaced since), hence saved.
  model_.kinematics(state_.t, state_.q, state_.qdot, state_.qddot, kin_);
}

// --- reporting --------------------------------------------------------------------------------

RigidBodyReport RigidBodySystem::bodyReport(int b) const {
  MFSI_CHECK(b >= 0 && b < model_.nBodies(), "rigid system: no body with index " << b);
  const RigidBodyKinematics& k = kin_.bodies[b];
  RigidBodyReport r;
  r.name = model_.bodyName(b);
  r.position = k.com;
  r.orientation = k.frame.rotation;
  r.eulerAngles = rigidEulerAngles(k.frame.rotation);
  r.velocity = k.comVelocity;
  r.angularVelocity = k.frame.omega;
  r.acceleration = k.comAcceleration;
  r.angularAcceleration = k.frame.alpha;
  r.force = loads_[b].force;
  r.moment = loads_[b].moment;
  return r;
}

Eigen::MatrixXd RigidBodySystem::massMatrix() const {
  Eigen::MatrixXd M;
  Eigen::VectorXd Q;
  RigidTreeKinematics kin;
  std::vector<RigidBodyLoad> loads;
  evaluate(state_.t, state_.q, state_.qdot, M, Q, kin, loads);
  return M;
}

double RigidBodySystem::kineticEnergy() const {
  double e = 0;
  for (int b = 0; b < model_.nBodies(); ++b) {
    const RigidBodyKinematics& k = kin_.bodies[b];
    const Eigen::Vector3d& w = k.frame.omega;
    e += 0.5 * model_.mass(b) * k.comVelocity.squaredNorm() + 0.5 * w.dot(model_.worldInertia(kin_, b) * w);
  }
  return e;
}

double RigidBodySystem::potentialEnergy() const {
  double e = restraints_.potentialEnergy(kin_);
  for (int b = 0; b < model_.nBodies(); ++b) e -= model_.mass(b) * options_.gravity.dot(kin_.bodies[b].com);
  return e;
}

std::map<std::string, double> RigidBodySystem::metrics() const {
  std::map<std::string, double> m;
  m["time"] = state_.t;
  m["steps"] = static_cast<double>(steps_);
  m["kineticEnergy"] = kineticEnergy();
  m["potentialEnergy"] = potentialEnergy();
  m["totalEnergy"] = m["kineticEnergy"] + m["potentialEnergy"];
  m["solver.iterations"] = lastIterations_;
  m["solver.maxIterations"] = maxIterationsUsed_;
  double maxDisp = 0;
  static const char* xyz[3] = {"x", "y", "z"};
  for (int b = 0; b < model_.nBodies(); ++b) {
    const RigidBodyReport r = bodyReport(b);
    const std::string p = "body." + r.name + ".";
    for (int i = 0; i < 3; ++i) {
      const std::string c = xyz[i];
      m[p + c] = r.position[i];
      m[p + "v" + c] = r.velocity[i];
      m[p + "a" + c] = r.acceleration[i];
      m[p + "w" + c] = r.angularVelocity[i];
      m[p + "F" + c] = r.force[i];
      m[p + "M" + c] = r.moment[i];
    }
    m[p + "roll"] = r.eulerAngles[0];
    m[p + "pitch"] = r.eulerAngles[1];
    m[p + "yaw"] = r.eulerAngles[2];
    m[p + "displacement"] = (r.position - initialCom_[b]).norm();
    m[p + "rotation"] = rotationAngle(r.orientation * initialRotation_[b].transpose());
    m[p + "maxDisplacement"] = maxDisplacement_[b];
    m[p + "maxRotation"] = maxRotation_[b];
    maxDisp = std::max(maxDisp, maxDisplacement_[b]);
    const auto& axes = model_.jointAxes(b);
    for (std::size_t k = 0; k < axes.size(); ++k) {
      const int d = model_.axisDof(b, static_cast<int>(k));
      if (d < 0) continue;
      m[p + "q" + std::to_string(k)] = state_.q[d];
      m[p + "qdot" + std::to_string(k)] = state_.qdot[d];
    }
  }
  m["maxDisplacement"] = maxDisp;
  restraints_.addMetrics(kin_, m);
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    const Constraint& k = constraints_[c];
    const std::string p = "restraint." + k.name + ".";
    m[p + "torque"] = constraintTorque_[c];
    m[p + "angle"] = state_.q[k.dof];
    m[p + "error"] = state_.q[k.dof] - k.angle(state_.t);
  }
  return m;
}

void RigidBodySystem::writeCsvHeader(std::ostream& os) {
  os << "time,body,x,y,z,roll,pitch,yaw,r00,r01,r02,r10,r11,r12,r20,r21,r22,vx,vy,vz,wx,wy,wz,ax,ay,az,"
        "alphax,alphay,alphaz,Fx,Fy,Fz,Mx,My,Mz\n";
}

void RigidBodySystem::writeCsvRows(std::ostream& os) const {
  const std::ios_base::fmtflags flags = os.flags();
  const std::streamsize precision = os.precision();
  os << std::setprecision(12);
  auto put = [&os](const Eigen::Vector3d& v) { os << ',' << v[0] << ',' << v[1] << ',' << v[2]; };
  for (int b = 0; b < model_.nBodies(); ++b) {
    const RigidBodyReport r = bodyReport(b);
    os << state_.t << ',' << r.name;
    put(r.position);
    put(r.eulerAngles);
    for (int i = 0; i < 3; ++i) put(r.orientation.row(i).transpose());
    put(r.velocity);
    put(r.angularVelocity);
    put(r.acceleration);
    put(r.angularAcceleration);
    put(r.force);
    put(r.moment);
    os << '\n';
  }
  os.flags(flags);
  os.precision(precision);
}

}  // namespace mfsi
