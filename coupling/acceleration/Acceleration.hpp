#pragma once
/// \file
/// \brief Acceleration of the coupling fixed point x = H(x) of one time step.
///
/// Design rationale (after preCICE's `acceleration/` module): the orchestrator sees only this small
/// interface. A coupling iteration takes the interface unknowns x (membrane node displacements,
/// rigid-body DOFs, in one vector of named blocks), runs structure -> mesh motion -> fluid ->
/// loads and gets H(x) = xt; the acceleration turns (x, xt) into the next x. The methods differ in
/// how much history they keep: constant relaxation none, Aitken one scalar, quasi-Newton methods
/// the differences of past iterates (QuasiNewton owns them, with the QR factorisation and its
/// filter; IqnIls is the least-squares Jacobian update on top). All vectors are host vectors of
/// this rank's interface entries; every inner product is a local sum completed by
/// `SolverComm::globalSum`, so a distributed interface needs no change here.
#include "core/io/Checkpoint.hpp"
#include "kernels/Blas.hpp"

#include <Eigen/Dense>

#include <memory>
#include <string>
#include <vector>

namespace mfsi::coupling {

using InterfaceVector = Eigen::VectorXd;

/// \brief One named block of the interface vector (e.g. "membrane:panel" displacements, "body:frame"
/// DOFs). Quasi-Newton methods scale each block by its own norm so mixed units weigh alike.
struct InterfaceBlock {
  std::string name;
  Eigen::Index offset = 0;
  Eigen::Index size = 0;
};

enum class AccelerationMethod {
  Constant,  ///< x <- x + omega (xt - x), omega = omegaInit
  Aitken,    ///< Aitken's Delta^2 (Irons & Tuck 1969; Kuettler & Wall 2008), omega in [omegaMin, 1]
  IqnIls,    ///< interface quasi-Newton, inverse Jacobian by least squares (Degroote et al. 2009)
};

/// The inverse Jacobian a quasi-Newton method (iqnMaxCols > 0) builds.
enum class IqnJacobian {
  LeastSquares,  ///< IQN-ILS: W V^+ from the history alone (columns of past steps by iqnReuseCols)
  /// IQN-IMVJ (Lindner, Mehl & Uekermann 2015): the last step's whole inverse Jacobian J_prev,
  /// updated by this step's history, J = J_prev + (W - J_prev V) V^+: what past steps learnt is
  /// kept beyond the reused columns, and the step's first pass is already a quasi-Newton step.
  /// Kept in low-rank form (at most iqnJacobianRank columns), never as an n x n matrix.
  MultiVector,
};

/// \brief Options of the `coupling` section (the seed's names; `mfsi check --describe` documents them).
struct AccelerationOptions {
  AccelerationMethod method = AccelerationMethod::Aitken;
  double omegaInit = 0.1;  ///< relaxation of a step's first iteration (Aitken, IQN-ILS) or always (Constant)
  double omegaMin = 0.05;  ///< Aitken's lower bound on omega
  int iqnMaxCols = 0;      ///< most history columns IQN-ILS keeps (> 0 selects IQN-ILS)
  int iqnReuseCols = 0;    ///< past time steps whose columns IQN-ILS keeps (0: history reset each step)
  IqnJacobian iqnJacobian = IqnJacobian::LeastSquares;
  /// QR2 filter: a column whose part orthogonal to the newer ones is below iqnFilterEps times its
  /// norm is dropped (it adds nothing but ill-conditioning).
  double iqnFilterEps = 1e-2;
  /// Step-size limiter: a quasi-Newton update larger than this (infinity norm, the interface's
  /// units) is unphysical; the iteration falls back to an Aitken step instead. 0: no limit.
  double maxUpdate = 0;
  /// Stall detector: the residual not below its smallest value of the step for this many
  /// iterations in a row restarts the history (columns, omega). 0: off. Quasi-Newton residuals
  /// need not fall monotonically (an unstable 12-unknown affine map stalls 5 passes on its way to
  /// the exact answer at pass 13), hence a generous default.
  int stallIterations = 10;
  /// IQN-IMVJ: the most columns of the low-rank part of the carried inverse Jacobian. Past it the
  /// part is compressed by a truncated SVD to its largest half.
  int iqnJacobianRank = 400;
};

/// \brief What one `update` did (steps.csv reports it).
struct AccelerationReport {
  double residualNorm = 0;  ///< ||xt - x||_2 over the whole interface (unscaled)
  double omega = 1;         ///< relaxation used (quasi-Newton steps: 1)
  int columns = 0;          ///< history columns used by a quasi-Newton step (0 for a relaxation step)
  int dropped = 0;          ///< columns the QR filter dropped in this update
  bool fellBack = false;    ///< the quasi-Newton step was rejected by the limiter: relaxation used
  bool restarted = false;   ///< the stall detector cleared the history before this update
};

/// \brief The acceleration interface.
class Acceleration {
 public:
  Acceleration(const AccelerationOptions& options, std::vector<InterfaceBlock> layout, const SolverComm& comm);
  virtual ~Acceleration() = default;
  Acceleration(const Acceleration&) = delete;
  Acceleration& operator=(const Acceleration&) = delete;

  /// \brief Start a time step: the iteration count restarts; history older than the method keeps is
  /// dropped.
  virtual void beginStep();
  /// \brief x went into the coupling pass, xt = H(x) came out: overwrite x with the next iterate.
  AccelerationReport update(const InterfaceVector& xt, InterfaceVector& x);
  /// \brief The step's iterations are over (converged or not).
  virtual void endStep() {}
  /// \brief What the method carries from one time step to the next (the quasi-Newton columns of
  /// past steps), for a checkpoint. Checkpoints are written between steps, and everything else
  /// restarts with each step (beginStep), so relaxation methods keep nothing.
  virtual void saveState(io::StateWriter& /*w*/) const {}
  virtual void loadState(const io::StateReader& /*r*/) {}
  /// \brief Forget what was learnt in this step (the next update is a first one): the caller
  /// replaced the iterate the last update asked for (e.g. the mesh could not follow it).
  void resetHistory() { restart(); }

  const AccelerationOptions& options() const { return options_; }
  const std::vector<InterfaceBlock>& layout() const { return layout_; }
  /// Iterations (calls of update) in the current step.
  int iteration() const { return iteration_; }
  /// \brief Global dot product of two interface vectors.
  double dot(const InterfaceVector& a, const InterfaceVector& b) const;
  double norm(const InterfaceVector& a) const;

 protected:
  /// The method's step: r = xt - x (given), x to be overwritten. `report` has residualNorm set.
  virtual void step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
                    AccelerationReport& report) = 0;
  /// Forget what the method learnt in this step (the stall detector's restart).
  virtual void restart() {}

  AccelerationOptions options_;
  std::vector<InterfaceBlock> layout_;
  SolverComm comm_;
  Eigen::Index size_ = 0;

 private:
  int iteration_ = 0;
  double bestResidual_ = 0;
  int sinceBest_ = 0;
};

/// \brief x <- x + omega r with a fixed omega.
class ConstantRelaxation final : public Acceleration {
 public:
  using Acceleration::Acceleration;

 protected:
  void step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
            AccelerationReport& report) override;
};

/// \brief The acceleration `options.method` names (IqnIls also when iqnMaxCols > 0).
std::unique_ptr<Acceleration> makeAcceleration(const AccelerationOptions& options,
                                               std::vector<InterfaceBlock> layout, const SolverComm& comm = {});

}  // namespace mfsi::coupling
