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
  columns_.erase(std::remove_if(columns_.begin(), columns_.end(), [&](const Column& c) { return c.step < oldest; }),
                 columns_.end());
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
}

void QuasiNewton::restart() {
  columns_.clear();
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
  for (Eigen::Index b = 0; b < nb; ++b) {
    const double nrm = std::sqrt(n2[b]) > 0 ? std::sqrt(n2[b]) : largest;
    blockWeight_[b] = nrm > 0 ? 1.0 / nrm : 1.0;
  }
}

InterfaceVector QuasiNewton::scaled(const InterfaceVector& a) const {
  InterfaceVector s = a;
  for (std::size_t b = 0; b < layout_.size(); ++b)
    s.segment(layout_[b].offset, layout_[b].size) *= blockWeight_[static_cast<Eigen::Index>(b)];
  return s;
}

void QuasiNewton::record(const InterfaceVector& xt, const InterfaceVector& r) {
  if (!havePrevious_) setScaling(r);
  if (havePrevious_) {
    columns_.push_front(Column{r - rPrevious_, xt - xtPrevious_, stepIndex_});
    while (static_cast<int>(columns_.size()) > options_.iqnMaxCols) columns_.pop_back();
  }
  rPrevious_ = r;
  xtPrevious_ = xt;
  havePrevious_ = true;
}

int QuasiNewton::factorise(Factorisation& f) {
  f.q.clear();
  std::vector<Eigen::VectorXd> rcols;  // column j of R (first j+1 entries)
  int dropped = 0;
  for (auto it = columns_.begin(); it != columns_.end();) {
    InterfaceVector q = scaled(it->v);
    const double original = norm(q);
    Eigen::VectorXd rc(static_cast<Eigen::Index>(f.q.size()) + 1);
    // Modified Gram-Schmidt, twice ("twice is enough", Giraud et al. 2005): the second pass
    // restores orthogonality that the first loses on nearly dependent columns.
    rc.setZero();
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < f.q.size(); ++i) {
        const double c = dot(f.q[i], q);
        rc[static_cast<Eigen::Index>(i)] += c;
        q -= c * f.q[i];
      }
    }
    const double rest = norm(q);
    if (!(original > 0) || !std::isfinite(rest) || rest <= options_.iqnFilterEps * original) {
      it = columns_.erase(it);  // QR2 filter: nothing new in this column
      ++dropped;
      continue;
    }
    rc[static_cast<Eigen::Index>(f.q.size())] = rest;
    f.q.push_back(q / rest);
    rcols.push_back(rc);
    ++it;
  }
  const auto k = static_cast<Eigen::Index>(f.q.size());
  f.r = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index j = 0; j < k; ++j) f.r.col(j).head(j + 1) = rcols[static_cast<std::size_t>(j)];
  return dropped;
}

void QuasiNewton::relax(const InterfaceVector& r, InterfaceVector& x, AccelerationReport& report) {
  report.omega = aitken_.omega();
  report.columns = 0;
  x += report.omega * r;
}

void IqnIls::step(const InterfaceVector& xt, const InterfaceVector& r, InterfaceVector& x,
                  AccelerationReport& report) {
  record(xt, r);
  aitken_.next(*this, r);  // the fallback's omega follows every pass
  if (columns_.empty()) {
    relax(r, x, report);
    return;
  }
  Factorisation f;
  report.dropped = factorise(f);
  const auto k = static_cast<Eigen::Index>(f.q.size());
  if (k == 0) {
    relax(r, x, report);
    return;
  }
  // alpha = argmin |S V alpha + S r| = -R^-1 Q^T S r.
  const InterfaceVector sr = scaled(r);
  Eigen::VectorXd qtr(k);
  for (Eigen::Index i = 0; i < k; ++i) qtr[i] = dot(f.q[static_cast<std::size_t>(i)], sr);
  const Eigen::VectorXd alpha = -f.r.triangularView<Eigen::Upper>().solve(qtr);
  InterfaceVector next = xt;
  for (Eigen::Index j = 0; j < k; ++j) next += alpha[j] * columns_[static_cast<std::size_t>(j)].w;
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
  report.columns = static_cast<int>(k);
}

}  // namespace mfsi::coupling
