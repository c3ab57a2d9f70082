#pragma once
/// \file
/// \brief Interface quasi-Newton acceleration: the history of iterate differences, its QR
/// factorisation and filter (QuasiNewton), and the least-squares inverse Jacobian (IqnIls).
#include "coupling/acceleration/Aitken.hpp"

#include <deque>

namespace mfsi::coupling {

/// \brief What every interface quasi-Newton method shares (preCICE's BaseQNAcceleration in spirit).
///
/// History: after each coupling pass k of a step (k >= 1) the column pair v = r_k - r_{k-1},
/// w = xt_k - xt_{k-1} joins the front (newest first); at most iqnMaxCols are kept, and columns of
/// the last iqnReuseCols steps survive beginStep. Columns are stored unscaled; the factorisation
/// works on block-scaled columns S v (each block divided by the norm of its residual at the
/// step's first pass, so membrane displacements and body DOFs weigh alike). The QR2 filter drops
/// for good any column whose part orthogonal to the newer ones is below iqnFilterEps of its norm.
///
/// The factorisation is kept up to date instead of rebuilt (as preCICE's QRFactorization): a new
/// column enters at the front by one Gram-Schmidt pass and Givens rotations, the oldest leave
/// from the back for free, a filtered column leaves by Givens rotations: O(n k) per pass for n
/// unknowns and k columns where a rebuild costs O(n k^2), which is what lets a long history (more
/// columns, more reused steps) pay for itself. It is rebuilt by modified Gram-Schmidt only when
/// the blocks' relative scaling changes (several blocks), after a restart or a checkpoint load,
/// or when a new column is numerically dependent on the history.
class QuasiNewton : public Acceleration {
 public:
  QuasiNewton(const AccelerationOptions& options, std::vector<InterfaceBlock> layout, const SolverComm& comm);
  void beginStep() override;
  /// The columns kept for later steps (iqnReuseCols) and the step count that ages them.
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  /// Columns in the history now.
  int columns() const { return static_cast<int>(columns_.size()); }
  /// How far the kept factorisation is from the history (0 when none is kept): the largest of
  /// max |Q R - S V| / max |S V| and max |Q^T Q - I|. For tests.
  double factorisationDefect() const;

 protected:
  struct Column {
    InterfaceVector v, w;
    long step = 0;  ///< the time step it was made in
    InterfaceVector jv;  ///< IQN-IMVJ only: J_prev v with the J_prev of this step (empty elsewhere)
  };
  /// The thin QR factorisation S V = Q R of the filtered history.
  struct Factorisation {
    std::vector<InterfaceVector> q;
    Eigen::MatrixXd r;
  };

  void restart() override;
  /// Add the newest column pair (from the previous pass) and trim the history.
  void record(const InterfaceVector& xt, const InterfaceVector& r);
  /// Bring the factorisation of the scaled history up to date and filter it (filtered columns
  /// leave the history); returns how many it dropped. The result: `factorisation()`.
  int factorise();
  const Factorisation& factorisation() const { return qr_; }
  /// S a: the block scaling of this step.
  InterfaceVector scaled(const InterfaceVector& a) const;
  /// The diagonal of S, one weight per unknown.
  Eigen::VectorXd scaling() const;
  /// A relaxation step x <- x + omega r (Aitken's omega, or omegaInit without history).
  void relax(const InterfaceVector& r, InterfaceVector& x, AccelerationReport& report);
  /// IQN-ILS's alpha = argmin |S (V alpha + r)| on the current factorisation.
  Eigen::VectorXd coefficients(const InterfaceVector& r) const;
  /// x <- next, a quasi-Newton step with `columns` columns, unless the step-size limiter rejects it
  /// (non-finite, or beyond maxUpdate): then a relaxation step.
  void accept(const InterfaceVector& next, const InterfaceVector& r, int columns, InterfaceVector& x,
              AccelerationReport& report);

  std::deque<Column> columns_;
  AitkenOmega aitken_;
  long stepIndex_ = 0;

 private:
  void setScaling(const InterfaceVector& r);
  void rebuild();
  void insertFront(const InterfaceVector& sv);
  void removeColumn(std::size_t j);
  Eigen::VectorXd blockWeight_;  ///< per block of layout_
  Factorisation qr_;              ///< of the scaled columns_, in their order, while qrValid_
  std::vector<double> qrNorm_;    ///< |S v| of each column (the filter's reference)
  bool qrValid_ = false;
  bool havePrevious_ = false;
  InterfaceVector rPrevious_, xtPrevious_;
};

/// \brief IQN-ILS (Degroote, Bathe & Vierendeels 2009): x <- xt + W alpha with alpha minimising
/// |S (V alpha + r)|, i.e. the inverse Jacobian of the residual fitted to the history by least
/// squares. On an affine H it reaches the fixed point once the history spans the residuals: at
/// most n + 1 passes for n unknowns.
class IqnIls final : public QuasiNewton {
 public:
  using QuasiNewton::QuasiNewton;

 protected:
  void step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
            AccelerationReport& report) override;
};

/// \brief IQN-IMVJ (Lindner, Mehl & Uekermann 2015): x <- xt - J_prev r + (W - J_prev V) alpha with
/// alpha the least-squares coefficients of IQN-ILS and J_prev the inverse Jacobian of the previous
/// steps, J_prev <- J_prev + (W - J_prev V) V^+ at each step's end (V^+ = R^-1 Q^T S: J V = W on
/// every kept column, reused ones included). J_prev starts as (1 - omegaInit) I, a relaxation by
/// omegaInit in every direction no history has seen, so the first pass of the first step is the
/// relaxation step of IQN-ILS.
///
/// J_prev is never an n x n matrix: it is (1 - omegaInit) I + L R^T with L and R of n x m, each
/// step's update appending its columns (W - J_prev V and the rows of V^+), so a pass costs O(n m)
/// and any interface size works. Past iqnJacobianRank columns the low-rank part is compressed: a
/// truncated SVD of S L R^T S^-1 (the step's block scaling, so membrane displacements and body DOFs
/// weigh alike) keeps its largest half, and drops directions below 1e-12 of the largest. Until the
/// first compression J_prev is the dense update's exactly (to round-off).
class IqnImvj final : public QuasiNewton {
 public:
  /// Throws InputError on more than one rank (the compression is not distributed).
  IqnImvj(const AccelerationOptions& options, std::vector<InterfaceBlock> layout, const SolverComm& comm);
  void beginStep() override;
  void endStep() override;
  void saveState(io::StateWriter& w) const override;
  void loadState(const io::StateReader& r) override;
  /// The inverse Jacobian carried between steps, as a dense matrix. For tests (small n).
  Eigen::MatrixXd jacobian() const;
  /// Columns of its low-rank part now.
  Eigen::Index rank() const { return left_.cols(); }
  /// How often the low-rank part has been compressed.
  int compressions() const { return compressions_; }

 protected:
  void step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
            AccelerationReport& report) override;

 private:
  /// J_prev a.
  InterfaceVector apply(const InterfaceVector& a) const;
  /// The truncated SVD of the low-rank part (iqnJacobianRank / 2 columns at most).
  void compress();

  double diagonal_ = 1;        ///< J_prev = diagonal_ I + left_ right_^T
  Eigen::MatrixXd left_, right_;  ///< n x m each
  int compressions_ = 0;
  /// J_prev r of the step's previous pass: a new column's J_prev v is the difference of two of
  /// them, so no pass multiplies J_prev by the history. After each step's update J_prev v = w holds
  /// on every kept column, which is what carries them to the next step without a product either.
  InterfaceVector jrPrevious_;
  bool haveJr_ = false;
};

}  // namespace mfsi::coupling
