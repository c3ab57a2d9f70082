#include "coupling/acceleration/QuasiNewton.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi::coupling {

QuasiNewton::QuasiNewton(const AccelerationOptions& options, std::vector<InterfaceBlock> layout,
                         const SolverComm& comm)
    : Acceleration(options, std::move(layout), comm), aitken_(options) {
  MFSI_CHECK(options_.iqnMaxCols > 0, "coupling.iqnMaxCols must be > 0 for IQN-ILS");
  MFSI_CHECK(options_.iqnReuseCols >= 0, "coupling.iqnReuseCols must be >= 0");
  MFSI_CHECK(options_.iqnFilterEps >= 0 && options_.iqnFilterEps < 1, "coupling.iqnFilterEps must be in [0, 1)");
  blockWeight_ = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(layout_.size()));
}

void QuasiNewton::beginStep() {
  Acceleration::beginStep();
  ++stepIndex_;
  const long oldest = stepIndex_ - options_.iqnReuseCols;
  // Columns are newest first, so the ones that age out are at the back.
  while (!columns_.empty() && columns_.back().step < oldest) {
    columns_.pop_back();
    if (qrValid_) removeColumn(columns_.size());
  }
  MFSI_ASSERT(std::none_of(columns_.begin(), columns_.end(), [&](const Column& c) { return c.step < oldest; }),
              "IQN history out of step order");
  havePrevious_ = false;
  aitken_.reset();
}

void QuasiNewton::saveState(io::StateWriter& w) const {
  w.putInt("stepIndex", stepIndex_);
  w.putInt("size", size_);
  std::vector<double> v, wv;
  std::vector<std::int64_t> steps;
  for (const Column& c : columns_) {
    v.insert(v.end(), c.v.data(), c.v.data() + c.v.size());
    wv.insert(wv.end(), c.w.data(), c.w.data() + c.w.size());
    steps.push_back(c.step);
  }
  w.put("columnSteps", steps);
  w.put("V", v);
  w.put("W", wv);
  // The kept factorisation and the scaling it was made with: a restart continues bit for bit.
  w.put("blockWeight", std::vector<double>(blockWeight_.data(), blockWeight_.data() + blockWeight_.size()));
  w.putBool("qrValid", qrValid_);
  if (qrValid_) {
    std::vector<double> q, rr(qr_.r.data(), qr_.r.data() + qr_.r.size());
    for (const auto& c : qr_.q) q.insert(q.end(), c.data(), c.data() + c.size());
    w.put("Q", q);
    w.put("R", rr);
    w.put("qrNorm", qrNorm_);
  }
}

void QuasiNewton::loadState(const io::StateReader& r) {
  if (r.integer("size") != size_)
    throw InputError(r.where("size") + ": an interface of " + std::to_string(r.integer("size")) +
                     " unknowns, the run has " + std::to_string(size_) + " (another scene?)");
  stepIndex_ = static_cast<long>(r.integer("stepIndex"));
  const auto steps = r.ints("columnSteps");
  const long long n = static_cast<long long>(steps.size()) * size_;
  const auto v = r.doubles("V", n), wv = r.doubles("W", n);
  columns_.clear();
  for (std::size_t i = 0; i < steps.size(); ++i) {
    Column c;
    c.v = Eigen::Map<const InterfaceVector>(v.data() + i * size_, size_);
    c.w = Eigen::Map<const InterfaceVector>(wv.data() + i * size_, size_);
    c.step = static_cast<long>(steps[i]);
    columns_.push_back(std::move(c));
  }
  qrValid_ = false;
  if (r.has("blockWeight")) {
    const auto bw = r.doubles("blockWeight", blockWeight_.size());
    blockWeight_ = Eigen::Map<const Eigen::VectorXd>(bw.data(), static_cast<Eigen::Index>(bw.size()));
  }
  if (r.has("qrValid") && r.boolean("qrValid")) {
    const auto k = static_cast<long long>(columns_.size());
    const auto q = r.doubles("Q", k * size_), rr = r.doubles("R", k * k);
    qr_.q.clear();
    for (long long i = 0; i < k; ++i) qr_.q.push_back(Eigen::Map<const InterfaceVector>(q.data() + i * size_, size_));
    qr_.r = Eigen::Map<const Eigen::MatrixXd>(rr.data(), static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k));
    qrNorm_ = r.doubles("qrNorm", k);
    qrValid_ = true;
  }
}

void QuasiNewton::restart() {
  columns_.clear();
  qrValid_ = false;
  havePrevious_ = false;
  aitken_.reset();
}

void QuasiNewton::setScaling(const InterfaceVector& r) {
  // Each block by the norm of its residual at the step's first pass; a block with none (not moved
  // yet) takes the largest other block's norm, so it neither dominates nor vanishes.
  const auto nb = static_cast<Eigen::Index>(layout_.size());
  Eigen::VectorXd n2(nb);
  for (Eigen::Index b = 0; b < nb; ++b) n2[b] = r.segment(layout_[b].offset, layout_[b].size).squaredNorm();
  comm_.globalSum(n2.data(), static_cast<int>(nb));
  const double largest = nb > 0 ? std::sqrt(n2.maxCoeff()) : 0.0;
  const Eigen::VectorXd before = blockWeight_;
  for (Eigen::Index b = 0; b < nb; ++b) {
    const double nrm = std::sqrt(n2[b]) > 0 ? std::sqrt(n2[b]) : largest;
    blockWeight_[b] = nrm > 0 ? 1.0 / nrm : 1.0;
  }
  // The same factor on every block scales R and the norms (Q stays); anything else: rebuild.
  if (!qrValid_ || nb == 0) return;
  const double f = blockWeight_[0] / before[0];
  for (Eigen::Index b = 1; b < nb; ++b)
    if (blockWeight_[b] != f * before[b]) {
      qrValid_ = false;
      return;
    }
  qr_.r *= f;
  for (double& n : qrNorm_) n *= f;
}

InterfaceVector QuasiNewton::scaled(const InterfaceVector& a) const { return scaling().cwiseProduct(a); }

Eigen::VectorXd QuasiNewton::scaling() const {
  Eigen::VectorXd s(size_);
  for (std::size_t b = 0; b < layout_.size(); ++b)
    s.segment(layout_[b].offset, layout_[b].size).setConstant(blockWeight_[static_cast<Eigen::Index>(b)]);
  return s;
}

void QuasiNewton::record(const InterfaceVector& xt, const InterfaceVector& r) {
  if (!havePrevious_) setScaling(r);
  if (havePrevious_) {
    columns_.push_front(Column{r - rPrevious_, xt - xtPrevious_, stepIndex_, InterfaceVector()});
    if (qrValid_) insertFront(scaled(columns_.front().v));
    while (static_cast<int>(columns_.size()) > options_.iqnMaxCols) {
      columns_.pop_back();
      if (qrValid_) removeColumn(columns_.size());
    }
  }
  rPrevious_ = r;
  xtPrevious_ = xt;
  havePrevious_ = true;
}

void QuasiNewton::rebuild() {
  qr_.q.clear();
  qrNorm_.clear();
  std::vector<Eigen::VectorXd> rcols;  // column j of R (first j+1 entries)
  for (auto it = columns_.begin(); it != columns_.end();) {
    InterfaceVector q = scaled(it->v);
    const double original = norm(q);
    Eigen::VectorXd rc(static_cast<Eigen::Index>(qr_.q.size()) + 1);
    // Modified Gram-Schmidt, twice ("twice is enough", Giraud et al. 2005): the second pass
    // restores orthogonality that the first loses on nearly dependent columns.
    rc.setZero();
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < qr_.q.size(); ++i) {
        const double c = dot(qr_.q[i], q);
        rc[static_cast<Eigen::Index>(i)] += c;
        q -= c * qr_.q[i];
      }
    }
    const double rest = norm(q);
    if (!(original > 0) || !std::isfinite(rest) || rest <= options_.iqnFilterEps * original) {
      it = columns_.erase(it);  // QR2 filter: nothing new in this column
      continue;
    }
    rc[static_cast<Eigen::Index>(qr_.q.size())] = rest;
    qr_.q.push_back(q / rest);
    qrNorm_.push_back(original);
    rcols.push_back(rc);
    ++it;
  }
  const auto k = static_cast<Eigen::Index>(qr_.q.size());
  qr_.r = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index j = 0; j < k; ++j) qr_.r.col(j).head(j + 1) = rcols[static_cast<std::size_t>(j)];
  qrValid_ = true;
}

namespace {
/// Givens rotation (c, s) with c a + s b = hypot(a, b), -s a + c b = 0.
std::pair<double, double> givens(double a, double b) {
  const double h = std::hypot(a, b);
  return h > 0 ? std::make_pair(a / h, b / h) : std::make_pair(1.0, 0.0);
}
/// Rows i and i + 1 of R by (c, s) from column `from` on, and the basis columns the same way
/// (Q R is unchanged: Q G^T G R).
void rotate(Eigen::MatrixXd& R, std::vector<InterfaceVector>& q, Eigen::Index i, double c, double s,
            Eigen::Index from) {
  for (Eigen::Index j = from; j < R.cols(); ++j) {
    const double a = R(i, j), b = R(i + 1, j);
    R(i, j) = c * a + s * b;
    R(i + 1, j) = -s * a + c * b;
  }
  InterfaceVector& qa = q[static_cast<std::size_t>(i)];
  InterfaceVector& qb = q[static_cast<std::size_t>(i + 1)];
  const InterfaceVector t = qa;
  qa = c * t + s * qb;
  qb = -s * t + c * qb;
}
}  // namespace

void QuasiNewton::insertFront(const InterfaceVector& sv) {
  const auto k = static_cast<Eigen::Index>(qr_.q.size());
  const double original = norm(sv);
  InterfaceVector u = sv;
  Eigen::VectorXd s = Eigen::VectorXd::Zero(k);
  for (int pass = 0; pass < 2; ++pass)
    for (Eigen::Index i = 0; i < k; ++i) {
      const double c = dot(qr_.q[static_cast<std::size_t>(i)], u);
      s[i] += c;
      u -= c * qr_.q[static_cast<std::size_t>(i)];
    }
  const double rho = norm(u);
  if (!(original > 0) || !std::isfinite(rho) || rho <= 1e-12 * original) {
    qrValid_ = false;  // dependent on the history (or degenerate): factorise() rebuilds and filters
    return;
  }
  // [S v, S V] = [Q, u / rho] T with T = [[s, R], [rho, 0]]; rotations from the bottom up make T
  // upper triangular.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k + 1, k + 1);
  T.col(0).head(k) = s;
  T(k, 0) = rho;
  T.block(0, 1, k, k) = qr_.r;
  qr_.q.push_back(u / rho);
  for (Eigen::Index i = k; i >= 1; --i) {
    const auto [c, sn] = givens(T(i - 1, 0), T(i, 0));
    rotate(T, qr_.q, i - 1, c, sn, 0);
    T(i, 0) = 0;
  }
  qr_.r = T;
  qrNorm_.insert(qrNorm_.begin(), original);
}

void QuasiNewton::removeColumn(std::size_t j) {
  const auto k = static_cast<Eigen::Index>(qr_.q.size());
  const auto jj = static_cast<Eigen::Index>(j);
  MFSI_ASSERT(jj < k, "IQN: removing column " << j << " of " << k);
  // Without column j, R is upper Hessenberg from column j on: rotations restore it.
  Eigen::MatrixXd R(k, k - 1);
  R.leftCols(jj) = qr_.r.leftCols(jj);
  R.rightCols(k - 1 - jj) = qr_.r.rightCols(k - 1 - jj);
  for (Eigen::Index i = jj; i < k - 1; ++i) {
    const auto [c, sn] = givens(R(i, i), R(i + 1, i));
    rotate(R, qr_.q, i, c, sn, i);
    R(i + 1, i) = 0;
  }
  qr_.r = R.topRows(k - 1);
  qr_.q.pop_back();
  qrNorm_.erase(qrNorm_.begin() + jj);
}

double QuasiNewton::factorisationDefect() const {
  if (!qrValid_ || qr_.q.empty()) return 0;
  const auto k = static_cast<Eigen::Index>(qr_.q.size());
  double scale = 0, defect = 0;
  for (Eigen::Index j = 0; j < k; ++j) {
    const InterfaceVector sv = scaled(columns_[static_cast<std::size_t>(j)].v);
    InterfaceVector qr = InterfaceVector::Zero(sv.size());
    for (Eigen::Index i = 0; i <= j; ++i) qr += qr_.r(i, j) * qr_.q[static_cast<std::size_t>(i)];
    scale = std::max(scale, sv.cwiseAbs().maxCoeff());
    defect = std::max(defect, (qr - sv).cwiseAbs().maxCoeff());
  }
  double orth = 0;
  for (Eigen::Index i = 0; i < k; ++i)
    for (Eigen::Index j = 0; j < k; ++j)
      orth = std::max(orth, std::abs(dot(qr_.q[static_cast<std::size_t>(i)], qr_.q[static_cast<std::size_t>(j)]) -
                                     (i == j ? 1.0 : 0.0)));
  return std::max(scale > 0 ? defect / scale : defect, orth);
}

int QuasiNewton::factorise() {
  const std::size_t before = columns_.size();
  if (!qrValid_) {
    rebuild();
    return static_cast<int>(before - columns_.size());
  }
  // QR2 filter on the kept factorisation: |R(i, i)| is column i's part orthogonal to the newer ones.
  for (std::size_t i = 0; i < columns_.size();) {
    const double d = std::abs(qr_.r(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)));
    if (!(qrNorm_[i] > 0) || !std::isfinite(d) || d <= options_.iqnFilterEps * qrNorm_[i]) {
      columns_.erase(columns_.begin() + static_cast<std::ptrdiff_t>(i));
      removeColumn(i);
      continue;
    }
    ++i;
  }
  return static_cast<int>(before - columns_.size());
}

void QuasiNewton::relax(const InterfaceVector& r, InterfaceVector& x, AccelerationReport& report) {
  report.omega = aitken_.omega();
  report.columns = 0;
  x += report.omega * r;
}

Eigen::VectorXd QuasiNewton::coefficients(const InterfaceVector& r) const {
  // alpha = argmin |S V alpha + S r| = -R^-1 Q^T S r.
  const Factorisation& f = qr_;
  const auto k = static_cast<Eigen::Index>(f.q.size());
  const InterfaceVector sr = scaled(r);
  Eigen::VectorXd qtr(k);
  for (Eigen::Index i = 0; i < k; ++i) qtr[i] = dot(f.q[static_cast<std::size_t>(i)], sr);
  return -f.r.triangularView<Eigen::Upper>().solve(qtr);
}

void QuasiNewton::accept(const InterfaceVector& next, const InterfaceVector& r, int columns, InterfaceVector& x,
                         AccelerationReport& report) {
  // Step-size limiter: a non-finite or unphysically large update falls back to relaxation.
  double largest = (next - x).cwiseAbs().maxCoeff();
  largest = comm_.globalMax(largest);
  if (!std::isfinite(largest) || (options_.maxUpdate > 0 && largest > options_.maxUpdate)) {
    report.fellBack = true;
    relax(r, x, report);
    return;
  }
  x = next;
  report.omega = 1;
  report.columns = columns;
}

void IqnIls::step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
                  AccelerationReport& report) {
  record(xt, r);
  aitken_.next(*this, r);  // the fallback's omega follows every pass
  if (columns_.empty()) {
    relax(r, x, report);
    return;
  }
  report.dropped = factorise();
  const auto k = static_cast<Eigen::Index>(factorisation().q.size());
  if (k == 0) {
    relax(r, x, report);
    return;
  }
  const Eigen::VectorXd alpha = coefficients(r);
  InterfaceVector next = xt;
  for (Eigen::Index j = 0; j < k; ++j) next += alpha[j] * columns_[static_cast<std::size_t>(j)].w;
  accept(next, r, static_cast<int>(k), x, report);
}

IqnImvj::IqnImvj(const AccelerationOptions& options, std::vector<InterfaceBlock> layout, const SolverComm& comm)
    : QuasiNewton(options, std::move(layout), comm) {
  if (comm_.ranks() > 1)
    throw InputError("coupling.iqnJacobian: multiVector runs on one rank (its compression is not distributed)");
  MFSI_CHECK(options_.iqnJacobianRank >= 2, "coupling.iqnJacobianRank must be >= 2");
  // Where the history has seen nothing, the step is a relaxation by omegaInit: x~ - (1 - omega) r =
  // x + omega r. (With J = 0 there it would be the plain fixed-point step, which a strong added
  // mass makes unstable: the tube takes 6.5 instead of 5.5-5.9 iterations per step.)
  diagonal_ = 1 - options_.omegaInit;
  left_.resize(size_, 0);
  right_.resize(size_, 0);
}

void IqnImvj::beginStep() {
  QuasiNewton::beginStep();
  haveJr_ = false;
}

InterfaceVector IqnImvj::apply(const InterfaceVector& a) const {
  InterfaceVector ja = diagonal_ * a;
  if (left_.cols() > 0) ja.noalias() += left_ * (right_.transpose() * a);
  return ja;
}

Eigen::MatrixXd IqnImvj::jacobian() const {
  Eigen::MatrixXd j = left_ * right_.transpose();
  j.diagonal().array() += diagonal_;
  return j;
}

void IqnImvj::step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
                   AccelerationReport& report) {
  record(xt, r);
  const InterfaceVector jr = apply(r);
  if (!columns_.empty() && columns_.front().jv.size() == 0) {  // the column record() just made
    // record() pairs a pass only with an earlier pass of the same step, whose J r is kept.
    MFSI_ASSERT(haveJr_, "IQN-IMVJ: a new column without the previous pass's J r");
    columns_.front().jv = jr - jrPrevious_;
  }
  jrPrevious_ = jr;
  haveJr_ = true;
  aitken_.next(*this, r);
  report.dropped = columns_.empty() ? 0 : factorise();
  const auto k = columns_.empty() ? Eigen::Index(0) : static_cast<Eigen::Index>(factorisation().q.size());
  // next = xt + W alpha - J_prev (r + V alpha), alpha IQN-ILS's coefficients.
  InterfaceVector next = xt - jr;
  if (k > 0) {
    const Eigen::VectorXd alpha = coefficients(r);
    for (Eigen::Index j = 0; j < k; ++j) {
      const Column& c = columns_[static_cast<std::size_t>(j)];
      next += alpha[j] * (c.w - c.jv);
    }
  }
  accept(next, r, static_cast<int>(k), x, report);
}

void IqnImvj::endStep() {
  if (columns_.empty()) return;
  factorise();
  const Factorisation& f = factorisation();
  const auto k = static_cast<Eigen::Index>(f.q.size());
  if (k == 0) return;
  // J += Z V^+ with Z = W - J V (n x k) and V^+ = R^-1 Q^T S (k x n). The columns of earlier steps
  // have J v = w from the last update, so only this step's columns (a zero column of Z elsewhere)
  // enter: they join the low-rank part as columns of L (Z) and of R (rows of V^+).
  Eigen::MatrixXd QtS(k, size_);
  for (Eigen::Index j = 0; j < k; ++j)
    QtS.row(j) = scaled(f.q[static_cast<std::size_t>(j)]).transpose();  // (S q)^T = q^T S, S diagonal
  const Eigen::MatrixXd pinv = f.r.triangularView<Eigen::Upper>().solve(QtS);
  std::vector<Eigen::Index> fresh;
  for (Eigen::Index j = 0; j < k; ++j) {
    const Column& c = columns_[static_cast<std::size_t>(j)];
    if (c.jv != c.w) fresh.push_back(j);
  }
  const auto m0 = left_.cols(), m = static_cast<Eigen::Index>(fresh.size());
  if (m > 0) {
    left_.conservativeResize(Eigen::NoChange, m0 + m);
    right_.conservativeResize(Eigen::NoChange, m0 + m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const Eigen::Index j = fresh[static_cast<std::size_t>(i)];
      const Column& c = columns_[static_cast<std::size_t>(j)];
      left_.col(m0 + i) = c.w - c.jv;
      right_.col(m0 + i) = pinv.row(j).transpose();
    }
  }
  for (Column& c : columns_) c.jv = c.w;
  if (left_.cols() > options_.iqnJacobianRank) {
    compress();
    // The truncated J_prev no longer maps every kept column exactly: the next update restores J v = w.
    for (Column& c : columns_) c.jv = apply(c.v);
  }
}

void IqnImvj::compress() {
  // S L R^T S^-1 = (S L)(S^-1 R)^T = Qa Ra Rb^T Qb^T, and the SVD of the small Ra Rb^T = U s V^T
  // gives the best low-rank approximation: L = S^-1 Qa U s, R = S Qb V on the kept directions.
  const Eigen::VectorXd s = scaling();
  const Eigen::Index n = size_, m = left_.cols();
  const Eigen::MatrixXd a = s.asDiagonal() * left_;
  const Eigen::MatrixXd b = s.cwiseInverse().asDiagonal() * right_;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qa(a), qb(b);
  const Eigen::Index ka = std::min(n, m);
  const Eigen::MatrixXd ra = qa.matrixQR().topRows(ka).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd rb = qb.matrixQR().topRows(ka).triangularView<Eigen::Upper>();
  // The SVD of C = Ra Rb^T from the symmetric eigenproblem of [0 C; C^T 0], whose eigenvalues are
  // +-sigma with eigenvectors [u; +-v] / sqrt(2): as accurate as an SVD (C^T C would square the
  // condition number), and Eigen's SelfAdjointEigenSolver compiles in a fraction of BDCSVD's time.
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(2 * ka, 2 * ka);
  aug.topRightCorner(ka, ka) = ra * rb.transpose();
  aug.bottomLeftCorner(ka, ka) = aug.topRightCorner(ka, ka).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(aug);
  // Ascending eigenvalues: the largest singular values are the last ones, largest first.
  const Eigen::VectorXd sigma = eig.eigenvalues().tail(ka).reverse();
  Eigen::Index keep = 0;
  const Eigen::Index most = options_.iqnJacobianRank / 2;
  while (keep < most && keep < sigma.size() && sigma[keep] > 1e-12 * sigma[0]) ++keep;
  const Eigen::MatrixXd vecs = std::sqrt(2.0) * eig.eigenvectors().rightCols(keep).rowwise().reverse();
  // The Householder reflectors applied to the kept directions alone (n x keep, not n x m).
  Eigen::MatrixXd ua = Eigen::MatrixXd::Zero(n, keep), ub = Eigen::MatrixXd::Zero(n, keep);
  ua.topRows(ka) = vecs.topRows(ka) * sigma.head(keep).asDiagonal();
  ub.topRows(ka) = vecs.bottomRows(ka);
  ua.applyOnTheLeft(qa.householderQ());
  ub.applyOnTheLeft(qb.householderQ());
  left_ = s.cwiseInverse().asDiagonal() * ua;
  right_ = s.asDiagonal() * ub;
  ++compressions_;
}

void IqnImvj::saveState(io::StateWriter& w) const {
  QuasiNewton::saveState(w);
  w.putInt("jacobianRank", left_.cols());
  w.putInt("jacobianCompressions", compressions_);
  w.put("jacobianLeft", std::vector<double>(left_.data(), left_.data() + left_.size()));
  w.put("jacobianRight", std::vector<double>(right_.data(), right_.data() + right_.size()));
  std::vector<double> jv;
  for (const Column& c : columns_) jv.insert(jv.end(), c.jv.data(), c.jv.data() + c.jv.size());
  w.put("JV", jv);
}

void IqnImvj::loadState(const io::StateReader& r) {
  QuasiNewton::loadState(r);
  if (r.has("inverseJacobian"))
    throw InputError(r.where("inverseJacobian") +
                     ": a dense IQN-IMVJ Jacobian, written by an earlier mfsi; this one keeps it in low-rank form "
                     "(restart from a checkpoint of this version, or start the run again)");
  const auto m = static_cast<Eigen::Index>(r.integer("jacobianRank"));
  if (m < 0) throw InputError(r.where("jacobianRank") + ": negative");
  compressions_ = static_cast<int>(r.integer("jacobianCompressions"));
  const auto l = r.doubles("jacobianLeft", static_cast<long long>(size_) * m);
  const auto rr = r.doubles("jacobianRight", static_cast<long long>(size_) * m);
  left_ = Eigen::Map<const Eigen::MatrixXd>(l.data(), size_, m);
  right_ = Eigen::Map<const Eigen::MatrixXd>(rr.data(), size_, m);
  const auto jv = r.doubles("JV", static_cast<long long>(columns_.size()) * size_);
  for (std::size_t i = 0; i < columns_.size(); ++i)
    columns_[i].jv = Eigen::Map<const InterfaceVector>(jv.data() + i * static_cast<std::size_t>(size_), size_);
  haveJr_ = false;
}

}  // namespace mfsi::coupling
