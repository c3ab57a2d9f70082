#include "coupling/motion/MeshColumns.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace mfsi::coupling {

namespace {

constexpr double kColumnMargin = M_PI / 6;  ///< how much further off than a column's next edge every other edge is
constexpr long long kLongestColumn = 100000;  ///< nodes; a longer line runs in circles
constexpr int kTraceWidth = 8;  ///< a line in flight between ranks: line, prev, cur (global ids), dir, s, count

/// A line being traced: its index (2 foot + side), the node it came from and the one it reached,
/// the direction of that last edge, the arc length to the reached node, and its nodes so far.
struct LineTrace {
  long long line = 0;
  lid_t prev = 0, cur = 0;
  double dir[3] = {0, 0, 0};
  double s = 0;
  long long count = 0;
};

enum LineStatus : int { kUntraced = 0, kKept = 1, kDropped = 2 };

class ColumnSearch {
 public:
  ColumnSearch(const ColumnGraph& g, const std::vector<gid_t>& feet) : g_(g), feet_(feet) {
    const lid_t nn = static_cast<lid_t>(g_.gid.size());
    for (lid_t i = 0; i < nn; ++i) local_.emplace(g_.gid[i], i);
    isFoot_.assign(static_cast<std::size_t>(nn), 0);
    for (gid_t f : feet_) {
      const auto it = local_.find(f);
      if (it != local_.end()) isFoot_[it->second] = 1;
    }
    status_.assign(2 * feet_.size(), kUntraced);
    handedOn_.assign(2 * feet_.size(), 0);
    length_.assign(2 * feet_.size(), 0.0);
    ranks_ = 1;
    if (g_.comm != MPI_COMM_NULL) MPI_Comm_size(g_.comm, &ranks_);
    outgoing_.resize(static_cast<std::size_t>(ranks_));
  }

  ColumnSet run() {
    for (std::size_t j = 0; j < feet_.size(); ++j) start(j);
    while (handOff()) {
    }
    agreeOnLines();
    return keptColumns();
  }

 private:
  /// The unit edge a -> b in `e`; returns its length.
  double unitEdge(lid_t a, lid_t b, double e[3]) const {
    double l = 0;
    for (int c = 0; c < 3; ++c) {
      e[c] = g_.points[3 * b + c] - g_.points[3 * a + c];
      l += e[c] * e[c];
    }
    l = std::sqrt(l);
    for (int c = 0; c < 3; ++c) e[c] /= l;
    return l;
  }

  /// The lines leaving foot j, started by the rank that owns it.
  void start(std::size_t j) {
    const auto it = local_.find(feet_[j]);
    if (it == local_.end() || it->second >= g_.nOwned) return;
    const lid_t f = it->second;
    std::vector<lid_t> leaving;
    for (lid_t k = g_.offsets[f]; k < g_.offsets[f + 1]; ++k)
      if (!isFoot_[g_.neighbours[k]]) leaving.push_back(g_.neighbours[k]);
    if (leaving.size() == 2) {
      double a[3], b[3];
      unitEdge(f, leaving[0], a);
      unitEdge(f, leaving[1], b);
      if (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] > -0.5) return;
    } else if (leaving.size() != 1) {
      return;
    }
    for (std::size_t side = 0; side < leaving.size(); ++side) {
      LineTrace t;
      t.line = static_cast<long long>(2 * j + side);
      t.prev = f;
      t.cur = leaving[side];
      t.s = unitEdge(f, t.cur, t.dir);
      advance(t);
    }
  }

  void finish(long long line, LineStatus status, double length) {
    status_[static_cast<std::size_t>(line)] = status;
    length_[static_cast<std::size_t>(line)] = length;
  }

  /// Follows the line until it ends, is dropped, or reaches a node another rank owns.
  void advance(LineTrace t) {
    for (;;) {
      const lid_t cur = t.cur;
      if (g_.fixed[cur]) {
        if (t.count >= 1)
          finish(t.line, kKept, t.s);
        else
          finish(t.line, kDropped, 0);
        return;
      }
      if (g_.sliding[cur] || isFoot_[cur] || t.count + 1 > kLongestColumn) {
        finish(t.line, kDropped, 0);
        return;
      }
      if (cur >= g_.nOwned) {  // its owner has all of its edges
        auto& out = outgoing_[static_cast<std::size_t>(g_.ghostOwner[cur - g_.nOwned])];
        const double packed[kTraceWidth] = {double(t.line), double(g_.gid[t.prev]), double(g_.gid[cur]), t.dir[0],
                                            t.dir[1], t.dir[2], t.s, double(t.count)};
        out.insert(out.end(), packed, packed + kTraceWidth);
        handedOn_[static_cast<std::size_t>(t.line)] = 1;
        return;
      }
      visits_.push_back({t.line, cur, t.s});
      ++t.count;
      lid_t best = -1;
      double bestDot = 0.5, secondDot = -2;
      for (lid_t k = g_.offsets[cur]; k < g_.offsets[cur + 1]; ++k) {
        const lid_t m = g_.neighbours[k];
        if (m == t.prev) continue;
        double e[3];
        unitEdge(cur, m, e);
        const double dot = e[0] * t.dir[0] + e[1] * t.dir[1] + e[2] * t.dir[2];
        if (dot > bestDot) {
          secondDot = bestDot;
          bestDot = dot;
          best = m;
        } else {
          secondDot = std::max(secondDot, dot);
        }
      }
      // The line goes on only where that edge is clearly the one: every other edge at least
      // 30 degrees further off (a layered mesh whose layers slope by up to 60 degrees).
      if (best < 0 || std::acos(std::min(1.0, secondDot)) < std::acos(std::min(1.0, bestDot)) + kColumnMargin) {
        finish(t.line, kDropped, 0);
        return;
      }
      t.s = t.s + unitEdge(cur, best, t.dir);
      t.prev = cur;
      t.cur = best;
    }
  }

  lid_t localNode(double id) const {
    const auto it = local_.find(static_cast<gid_t>(id));
    MFSI_CHECK(it != local_.end(), "mesh motion columns: a line reached node " << gid_t(id)
                                                                               << ", which is not on the owner's part");
    return it->second;
  }

  /// The lines in flight go to the ranks that own their next node, which trace them on. Returns
  /// whether any rank had one. Collective.
  bool handOff() {
    long long inFlight = 0;
    for (const auto& o : outgoing_) inFlight += static_cast<long long>(o.size());
    if (g_.comm == MPI_COMM_NULL) {
      MFSI_CHECK(inFlight == 0, "mesh motion columns: a line left the only rank's nodes");
      return false;
    }
    MPI_Allreduce(MPI_IN_PLACE, &inFlight, 1, MPI_LONG_LONG, MPI_SUM, g_.comm);
    if (inFlight == 0) return false;
    const std::size_t n = static_cast<std::size_t>(ranks_);
    std::vector<int> sendCount(n), recvCount(n), sendAt(n + 1, 0), recvAt(n + 1, 0);
    for (std::size_t r = 0; r < n; ++r) sendCount[r] = static_cast<int>(outgoing_[r].size());
    MPI_Alltoall(sendCount.data(), 1, MPI_INT, recvCount.data(), 1, MPI_INT, g_.comm);
    std::vector<double> send;
    for (std::size_t r = 0; r < n; ++r) {
      sendAt[r + 1] = sendAt[r] + sendCount[r];
      recvAt[r + 1] = recvAt[r] + recvCount[r];
      send.insert(send.end(), outgoing_[r].begin(), outgoing_[r].end());
      outgoing_[r].clear();
    }
    std::vector<double> recv(static_cast<std::size_t>(recvAt[n]));
    MPI_Alltoallv(send.data(), sendCount.data(), sendAt.data(), MPI_DOUBLE, recv.data(), recvCount.data(),
                  recvAt.data(), MPI_DOUBLE, g_.comm);
    for (std::size_t k = 0; k < recv.size(); k += kTraceWidth) {
      LineTrace t;
      t.line = static_cast<long long>(recv[k]);
      t.prev = localNode(recv[k + 1]);
      t.cur = localNode(recv[k + 2]);
      for (int c = 0; c < 3; ++c) t.dir[c] = recv[k + 3 + c];
      t.s = recv[k + 6];
      t.count = static_cast<long long>(recv[k + 7]);
      advance(t);
    }
    return true;
  }

  /// Every rank learns how each line ended (the rank where it ended says) and drops the lines that
  /// share a node with a kept line of an earlier foot.
  void agreeOnLines() {
    if (g_.comm != MPI_COMM_NULL) {
      MPI_Allreduce(MPI_IN_PLACE, status_.data(), static_cast<int>(status_.size()), MPI_INT, MPI_MAX, g_.comm);
      MPI_Allreduce(MPI_IN_PLACE, length_.data(), static_cast<int>(length_.size()), MPI_DOUBLE, MPI_SUM, g_.comm);
      MPI_Allreduce(MPI_IN_PLACE, handedOn_.data(), static_cast<int>(handedOn_.size()), MPI_INT, MPI_MAX, g_.comm);
    }
    // The pairs of traced lines through one node: a node is visited on the rank that owns it.
    std::vector<std::pair<lid_t, long long>> byNode;
    for (const Visit& v : visits_)
      if (status_[static_cast<std::size_t>(v.line)] == kKept) byNode.emplace_back(v.node, v.line);
    std::sort(byNode.begin(), byNode.end());
    std::vector<long long> pairs;  // (earlier, later)
    for (std::size_t a = 0; a < byNode.size();) {
      std::size_t b = a;
      while (b < byNode.size() && byNode[b].first == byNode[a].first) ++b;
      for (std::size_t i = a; i < b; ++i)
        for (std::size_t k = i + 1; k < b; ++k)
          if (byNode[i].second != byNode[k].second) {
            pairs.push_back(byNode[i].second);
            pairs.push_back(byNode[k].second);
          }
      a = b;
    }
    if (g_.comm != MPI_COMM_NULL) {
      int mine = static_cast<int>(pairs.size());
      std::vector<int> count(static_cast<std::size_t>(ranks_)), at(static_cast<std::size_t>(ranks_) + 1, 0);
      MPI_Allgather(&mine, 1, MPI_INT, count.data(), 1, MPI_INT, g_.comm);
      for (std::size_t r = 0; r < count.size(); ++r) at[r + 1] = at[r] + count[r];
      std::vector<long long> all(static_cast<std::size_t>(at.back()));
      MPI_Allgatherv(pairs.data(), mine, MPI_LONG_LONG, all.data(), count.data(), at.data(), MPI_LONG_LONG,
                     g_.comm);
      pairs.swap(all);
    }
    std::vector<std::vector<long long>> earlier(status_.size());
    for (std::size_t k = 0; k < pairs.size(); k += 2) {
      const long long a = std::min(pairs[k], pairs[k + 1]), b = std::max(pairs[k], pairs[k + 1]);
      earlier[static_cast<std::size_t>(b)].push_back(a);
    }
    for (std::size_t line = 0; line < status_.size(); ++line) {
      if (status_[line] != kKept) continue;
      for (long long a : earlier[line])
        if (status_[static_cast<std::size_t>(a)] == kKept) {
          status_[line] = kDropped;
          break;
        }
    }
  }

  ColumnSet keptColumns() const {
    ColumnSet set;
    for (const Visit& v : visits_) {
      const std::size_t line = static_cast<std::size_t>(v.line);
      if (status_[line] != kKept) continue;
      set.node.push_back(v.node);
      set.foot.push_back(static_cast<lid_t>(v.line / 2));
      set.weight.push_back(1 - v.s / length_[line]);
    }
    set.count = static_cast<lid_t>(std::count(status_.begin(), status_.end(), kKept));
    for (std::size_t line = 0; line < status_.size(); ++line)
      set.acrossRanks += status_[line] == kKept && handedOn_[line] != 0 ? 1 : 0;
    return set;
  }

  struct Visit {
    long long line;
    lid_t node;
    double s;  ///< arc length from the foot
  };

  const ColumnGraph& g_;
  const std::vector<gid_t>& feet_;
  std::unordered_map<gid_t, lid_t> local_;
  std::vector<char> isFoot_;
  std::vector<int> status_;       ///< LineStatus per line (2 foot + side)
  std::vector<double> length_;    ///< a kept line's length, to its far end
  std::vector<int> handedOn_;     ///< per line: 1 once it went from one rank to another
  std::vector<Visit> visits_;     ///< the owned nodes the lines passed, in order
  std::vector<std::vector<double>> outgoing_;  ///< lines in flight, per rank they go to
  int ranks_ = 1;
};

}  // namespace

ColumnSet findColumns(const ColumnGraph& graph, const std::vector<gid_t>& feet) {
  return ColumnSearch(graph, feet).run();
}

}  // namespace mfsi::coupling
