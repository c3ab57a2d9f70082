#include "kernels/DistributedAmg.hpp"

#include "core/Error.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/RowExchange.hpp"
#include "kernels/Blas.hpp"
#include "kernels/CsrBuild.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <type_traits>

namespace mfsi {

namespace {

using HostSpace = Kokkos::HostSpace;
using Row = std::vector<std::pair<gid_t, double>>;

/// Host CSR of one level: owned rows, local column indices (owned, then ghosts).
struct HostCsr {
  lid_t nRows = 0, nCols = 0;
  std::vector<lid_t> ptr{0}, col;
  std::vector<double> val;
};

template <class T>
Kokkos::View<T*, MemSpace> deviceCopy(const std::vector<T>& v, const std::string& label) {
  Kokkos::View<T*, MemSpace> d(label, v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(d, h);
  return d;
}

/// The matrix on the device; with `rowRuns`, its row runs too (kernels/CsrMatrix: host backends
/// then sweep runs of rows with one column pattern; the same bits as the row kernels).
/// `sameSparsity`: a matrix of h's sparsity whose runs (if it has any) are taken instead of built.
CsrMatrix toDevice(const HostCsr& h, const std::string& label, bool rowRuns = false,
                   const CsrMatrix* sameSparsity = nullptr) {
  CsrMatrix M;
  M.nRows = h.nRows;
  M.nCols = h.nCols;
  M.rowPtr = deviceCopy(h.ptr, label + "::rowPtr");
  M.colIdx = deviceCopy(h.col, label + "::colIdx");
  M.values = deviceCopy(h.val, label + "::values");
  std::vector<lid_t> diag(h.nRows, -1);
  for (lid_t i = 0; i < h.nRows; ++i)
    for (lid_t p = h.ptr[i]; p < h.ptr[i + 1]; ++p)
      if (h.col[p] == i) diag[i] = p;
  M.diagIdx = deviceCopy(diag, label + "::diagIdx");
  if (rowRuns && kHostExec)
    M.runs = sameSparsity && sameSparsity->runs.count > 0 ? sameSparsity->runs : buildRowRuns(h.nRows, h.ptr, h.col, label);
  return M;
}

HostCsr hostCopy(const CsrMatrix& A) {
  HostCsr h;
  h.nRows = A.nRows;
  h.nCols = A.nCols;
  auto ptr = Kokkos::create_mirror_view_and_copy(HostSpace(), A.rowPtr);
  auto col = Kokkos::create_mirror_view_and_copy(HostSpace(), A.colIdx);
  auto val = Kokkos::create_mirror_view_and_copy(HostSpace(), A.values);
  h.ptr.assign(ptr.data(), ptr.data() + A.nRows + 1);
  h.col.assign(col.data(), col.data() + h.ptr.back());
  h.val.assign(val.data(), val.data() + h.ptr.back());
  return h;
}

/// The diagonal entry of every owned row (0 where a row has none).
std::vector<double> diagonalOf(const HostCsr& A) {
  std::vector<double> d(A.nRows, 0.0);
  for (lid_t i = 0; i < A.nRows; ++i)
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p)
      if (A.col[p] == i) d[i] = A.val[p];
  return d;
}

/// Greedy three-phase aggregation of the owned rows over their owned strong couplings
/// (|a_ij| >= theta sqrt(|a_ii a_jj|); theta = 0: every nonzero coupling). Every row gets an
/// aggregate (an isolated row is one of its own).
std::vector<lid_t> aggregateOwned(const HostCsr& A, double theta, lid_t& nAgg) {
  const lid_t n = A.nRows;
  const std::vector<double> d = diagonalOf(A);
  auto strong = [&](lid_t i, lid_t p) {
    const lid_t j = A.col[p];
    if (j == i || j >= n || A.val[p] == 0) return false;
    return std::abs(A.val[p]) >= theta * std::sqrt(std::abs(d[i] * d[j]));
  };
  std::vector<lid_t> agg(n, -1);
  nAgg = 0;
  for (lid_t i = 0; i < n; ++i) {  // roots whose strong neighbours are all free
    if (agg[i] >= 0) continue;
    bool free = true, any = false;
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p)
      if (strong(i, p)) {
        any = true;
        free = free && agg[A.col[p]] < 0;
      }
    if (!any || !free) continue;
    agg[i] = nAgg;
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p)
      if (strong(i, p)) agg[A.col[p]] = nAgg;
    ++nAgg;
  }
  const std::vector<lid_t> first = agg;
  for (lid_t i = 0; i < n; ++i) {  // leftovers join their strongest aggregated neighbour
    if (agg[i] >= 0) continue;
    double best = -1;
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p)
      if (strong(i, p) && first[A.col[p]] >= 0 && std::abs(A.val[p]) > best) {
        best = std::abs(A.val[p]);
        agg[i] = first[A.col[p]];
      }
  }
  for (lid_t i = 0; i < n; ++i) {  // the rest: new aggregates with their free strong neighbours
    if (agg[i] >= 0) continue;
    agg[i] = nAgg;
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p)
      if (strong(i, p) && agg[A.col[p]] < 0) agg[A.col[p]] = nAgg;
    ++nAgg;
  }
  return agg;
}

/// A structured lattice's extents (x fastest), and every owned row's cell on it.
struct LatticeRows {
  std::array<std::int64_t, 3> extent{0, 0, 0};
  std::vector<std::array<std::int64_t, 3>> at;  ///< owned rows; empty: not a lattice
  bool valid() const { return extent[0] > 0; }
};

/// The lattice of the fine level, or none. The candidate extents come from the smallest global-id
/// steps between coupled rows over all ranks (nx: the smallest above 1; nx ny: the next); then
/// every rank checks that each owned row holds its diagonal and exactly its in-range lattice
/// neighbours (by global id), all strong (`diagonal`: of every local row and ghost), and all
/// ranks must agree.
LatticeRows detectLattice(MPI_Comm comm, const HostCsr& A, const std::vector<gid_t>& gid, std::int64_t rows,
                          double theta, const std::vector<double>& diagonal) {
  const lid_t n = A.nRows;
  std::int64_t step[2] = {std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::max()};
  for (int pass = 0; pass < 2; ++pass) {
    const std::int64_t above = pass == 0 ? 1 : step[0];
    std::int64_t best = std::numeric_limits<std::int64_t>::max();
    for (lid_t i = 0; i < n; ++i)
      for (lid_t p = A.ptr[i]; p < A.ptr[i + 1]; ++p) {
        const std::int64_t d = std::llabs(gid[A.col[p]] - gid[i]);
        if (d > above) best = std::min(best, d);
      }
    if (comm != MPI_COMM_NULL) MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_INT64_T, MPI_MIN, comm);
    step[pass] = best;
    if (best == std::numeric_limits<std::int64_t>::max()) break;
  }
  LatticeRows L;
  const std::int64_t none = std::numeric_limits<std::int64_t>::max();
  if (step[0] == none) return L;  // no coupling beyond +-1: a line, left to greedy aggregation
  const std::int64_t nx = step[0], nxy = step[1] == none ? rows : step[1];
  if (nxy % nx != 0 || rows % nxy != 0) return L;
  const std::array<std::int64_t, 3> e{nx, nxy / nx, rows / nxy};
  const std::vector<double>& d = diagonal;
  int ok = 1;
  std::vector<std::array<std::int64_t, 3>> at(n);
  for (lid_t i = 0; i < n && ok; ++i) {
    const gid_t g = gid[i];
    at[i] = {g % e[0], (g / e[0]) % e[1], g / nxy};
    ok = g >= 0 && g < rows && d[i] != 0;
  }
  for (lid_t i = 0; i < n && ok; ++i) {
    const std::int64_t stride[3] = {1, e[0], nxy};
    int expected = 1;
    for (int k = 0; k < 3; ++k) expected += (at[i][k] > 0) + (at[i][k] + 1 < e[k]);
    if (A.ptr[i + 1] - A.ptr[i] != expected) ok = 0;
    for (lid_t p = A.ptr[i]; p < A.ptr[i + 1] && ok; ++p) {
      const lid_t j = A.col[p];
      if (j == i) continue;
      const std::int64_t delta = gid[j] - gid[i];
      bool neighbour = false;
      for (int k = 0; k < 3; ++k)
        neighbour = neighbour || (delta == stride[k] && at[i][k] + 1 < e[k]) || (delta == -stride[k] && at[i][k] > 0);
      ok = neighbour && std::abs(A.val[p]) >= theta * std::sqrt(std::abs(d[i] * d[j]));
    }
  }
  if (comm != MPI_COMM_NULL) MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, comm);
  if (!ok) return L;
  L.extent = e;
  L.at = std::move(at);
  return L;
}

/// Lattice-aligned aggregation of the owned rows: the rows in one cube of `factor` cells per
/// direction (1 in a direction of extent 1) form one aggregate, numbered in the cubes' lexicographic
/// order (x fastest); the coarse lattice (cube extents and positions) is returned in `coarse`.
std::vector<lid_t> aggregateLattice(const LatticeRows& fine, std::int64_t factor, lid_t& nAgg, LatticeRows& coarse) {
  std::array<std::int64_t, 3> f{}, ce{};
  for (int k = 0; k < 3; ++k) {
    f[k] = fine.extent[k] > 1 ? factor : 1;
    ce[k] = (fine.extent[k] + f[k] - 1) / f[k];
  }
  const std::size_t n = fine.at.size();
  std::vector<std::int64_t> key(n);
  for (std::size_t i = 0; i < n; ++i)
    key[i] = fine.at[i][0] / f[0] + ce[0] * (fine.at[i][1] / f[1] + ce[1] * (fine.at[i][2] / f[2]));
  std::vector<std::int64_t> cubes = key;
  std::sort(cubes.begin(), cubes.end());
  cubes.erase(std::unique(cubes.begin(), cubes.end()), cubes.end());
  std::vector<lid_t> agg(n);
  for (std::size_t i = 0; i < n; ++i)
    agg[i] = static_cast<lid_t>(std::lower_bound(cubes.begin(), cubes.end(), key[i]) - cubes.begin());
  nAgg = static_cast<lid_t>(cubes.size());
  coarse.extent = ce;
  coarse.at.resize(cubes.size());
  for (std::size_t a = 0; a < cubes.size(); ++a)
    coarse.at[a] = {cubes[a] % ce[0], (cubes[a] / ce[0]) % ce[1], cubes[a] / (ce[0] * ce[1])};
  return agg;
}

template <class S>
using SView = Kokkos::View<S*, MemSpace>;

/// A level operator in the cycle's precision S: a matrix's sparsity (and row runs) with its
/// values (S = double: the matrix's own; float: a rounded copy).
template <class S>
struct CycleMat {
  lid_t nRows = 0;
  IndexView rowPtr, colIdx;
  SView<S> val;
  CsrRowRuns runs;
  CsrGhostSplit split;  ///< empty: its products do not overlap the exchange of their x
};

template <class S>
CycleMat<S> cycleMat(const ExecSpace& exec, const CsrMatrix& M) {
  CycleMat<S> C;
  C.nRows = M.nRows;
  C.rowPtr = M.rowPtr;
  C.colIdx = M.colIdx;
  C.runs = M.runs;
  if constexpr (std::is_same<S, double>::value) {
    C.val = M.values;
  } else {
    C.val = SView<S>(Kokkos::view_alloc(Kokkos::WithoutInitializing, M.values.label() + "::float"), M.values.extent(0));
    const SView<S> v = C.val;
    const RealView m = M.values;
    Kokkos::parallel_for(
        "mfsi::kernels::damg::round", RangePolicy(exec, 0, static_cast<lid_t>(v.extent(0))),
        KOKKOS_LAMBDA(lid_t k) { v(k) = static_cast<S>(m(k)); });
  }
  return C;
}

/// y = alpha M x + beta y (beta = 0: y not read): blas::spmv's kernels in S.
template <class S>
void spmv(const ExecSpace& exec, S alpha, const CycleMat<S>& M, const SView<S>& x, S beta, const SView<S>& y) {
  blas::detail::spmvRows(exec, "mfsi::kernels::damg::spmv", alpha, M.nRows, M.runs, M.rowPtr, M.colIdx, M.val, x,
                         beta, y);
}

/// halo.exchange(x), then y = alpha M x + beta y; with M's ghost split, the exchange runs while
/// the rows that read no ghost are multiplied (the same y, bit for bit).
template <class S>
void exchangeAndMultiply(const ExecSpace& exec, const Halo& halo, S alpha, const CycleMat<S>& M, const SView<S>& x,
                         S beta, const SView<S>& y) {
  if (M.split.empty()) {
    halo.exchange(exec, x);
    spmv<S>(exec, alpha, M, x, beta, y);
    return;
  }
  const char* label = "mfsi::kernels::damg::spmv";
  halo.begin(exec, x);
  blas::detail::spmvRowSet(exec, label, alpha, M.runs, M.rowPtr, M.colIdx, M.val, x, beta, y, M.split,
                           CsrGhostSplit::kInterior);
  halo.end(exec, x);
  blas::detail::spmvRowSet(exec, label, alpha, M.runs, M.rowPtr, M.colIdx, M.val, x, beta, y, M.split,
                           CsrGhostSplit::kBoundary);
}

/// d = c * inv .* r on the first n entries.
template <class S>
void scaled(const ExecSpace& exec, lid_t n, S c, const SView<S>& inv, const SView<S>& r, const SView<S>& d) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::scaled", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { d(i) = c * inv(i) * r(i); });
}

/// d = a d + c inv .* r on the first n entries.
template <class S>
void chebyshevDirection(const ExecSpace& exec, lid_t n, S a, S c, const SView<S>& inv, const SView<S>& r,
                        const SView<S>& d) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::direction", RangePolicy(exec, 0, n),
      KOKKOS_LAMBDA(lid_t i) { d(i) = a * d(i) + c * inv(i) * r(i); });
}

/// r = b and d = c inv .* b on the first n entries: the residual and first Chebyshev direction of a
/// smoothing that starts from x = 0 (what b - A 0 and c inv .* r give, bit for bit, without the product).
template <class S>
void fromZero(const ExecSpace& exec, lid_t n, S c, const SView<S>& inv, const SView<S>& b, const SView<S>& r,
              const SView<S>& d) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::fromZero", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        const S bi = b(i);
        r(i) = bi;
        d(i) = c * inv(i) * bi;
      });
}

/// r = b - r on the first n entries.
template <class S>
void fromProduct(const ExecSpace& exec, lid_t n, const SView<S>& b, const SView<S>& r) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::residual", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { r(i) = b(i) - r(i); });
}

/// x += d on the first n entries.
template <class S>
void addTo(const ExecSpace& exec, lid_t n, const SView<S>& d, const SView<S>& x) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::add", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) { x(i) += d(i); });
}

/// dst = src on the first n entries, converted to dst's precision.
template <class D, class Src>
void convert(const ExecSpace& exec, lid_t n, const Src& src, const SView<D>& dst) {
  Kokkos::parallel_for(
      "mfsi::kernels::damg::convert", RangePolicy(exec, 0, n),
      KOKKOS_LAMBDA(lid_t i) { dst(i) = static_cast<D>(src(i)); });
}

/// x(i) = sum_k inv(i, k) b(k): the gathered coarsest solve of the owned rows, in a fixed order.
void denseRows(const ExecSpace& exec, const Kokkos::View<double**, MemSpace>& inv, const RealView& b,
               const RealView& x) {
  const lid_t n = static_cast<lid_t>(inv.extent(0)), m = static_cast<lid_t>(inv.extent(1));
  Kokkos::parallel_for(
      "mfsi::kernels::damg::coarsest", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t i) {
        double s = 0;
        for (lid_t k = 0; k < m; ++k) s += inv(i, k) * b(k);
        x(i) = s;
      });
}

/// Bytes of distinct allocations (DistributedAmg::memoryBytes): a View that two parts share (a
/// double cycle's vectors are its levels') counts once.
struct ByteCount {
  std::set<const void*> seen;
  std::size_t bytes = 0;
  template <class V>
  void view(const V& v) {
    if (v.data() != nullptr && seen.insert(static_cast<const void*>(v.data())).second)
      bytes += v.size() * sizeof(typename V::value_type);
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    bytes += v.capacity() * sizeof(T);
  }
  void runs(const CsrRowRuns& R) {
    view(R.start);
    view(R.offsetsAt);
    view(R.offsets);
    view(R.blockStart);
  }
  void csr(const CsrMatrix& M) {
    view(M.rowPtr);
    view(M.colIdx);
    view(M.diagIdx);
    view(M.values);
    runs(M.runs);
  }
  template <class S>
  void csr(const CycleMat<S>& M) {
    view(M.rowPtr);
    view(M.colIdx);
    view(M.val);
    runs(M.runs);
  }
};

/// A communicator of a few ranks, freed with its holder.
class GroupComm {
 public:
  GroupComm() = default;
  explicit GroupComm(MPI_Comm c) : comm_(c) {}
  GroupComm(GroupComm&& o) noexcept : comm_(o.comm_) { o.comm_ = MPI_COMM_NULL; }
  GroupComm& operator=(GroupComm&& o) noexcept {
    std::swap(comm_, o.comm_);
    return *this;
  }
  GroupComm(const GroupComm&) = delete;
  GroupComm& operator=(const GroupComm&) = delete;
  ~GroupComm() {
    int finalized = 1;
    MPI_Finalized(&finalized);
    if (comm_ != MPI_COMM_NULL && !finalized) MPI_Comm_free(&comm_);
  }
  MPI_Comm get() const { return comm_; }

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
};

template <class S>
MPI_Datatype mpiScalar() {
  return std::is_same<S, float>::value ? MPI_FLOAT : MPI_DOUBLE;
}

/// The first `owned` entries of `from` on every member of `group`, one after the other in member
/// order, into the first entries of `to` on the group's first member (MPI_Gatherv; `counts` and
/// `displs` are read there). Staged through host mirrors (no copy on host memory).
template <class S>
void gatherToFirst(const ExecSpace& exec, MPI_Comm group, const std::vector<int>& counts,
                   const std::vector<int>& displs, lid_t owned, const SView<S>& from, const SView<S>& to) {
  const auto src = Kokkos::subview(from, std::make_pair(0, owned));
  const auto dst = Kokkos::subview(to, std::make_pair(0, displs.empty() ? 0 : displs.back()));
  auto hs = Kokkos::create_mirror_view(src);
  auto hd = Kokkos::create_mirror_view(dst);
  exec.fence();
  Kokkos::deep_copy(hs, src);
  MPI_Gatherv(hs.data(), owned, mpiScalar<S>(), hd.data(), counts.data(), displs.data(), mpiScalar<S>(), 0, group);
  Kokkos::deep_copy(dst, hd);
}

/// The reverse of gatherToFirst: each member's rows of `from` (on the first member) into the first
/// `owned` entries of its `to` (MPI_Scatterv).
template <class S>
void scatterFromFirst(const ExecSpace& exec, MPI_Comm group, const std::vector<int>& counts,
                      const std::vector<int>& displs, lid_t owned, const SView<S>& from, const SView<S>& to) {
  const auto src = Kokkos::subview(from, std::make_pair(0, displs.empty() ? 0 : displs.back()));
  const auto dst = Kokkos::subview(to, std::make_pair(0, owned));
  auto hs = Kokkos::create_mirror_view(src);
  auto hd = Kokkos::create_mirror_view(dst);
  exec.fence();
  Kokkos::deep_copy(hs, src);
  MPI_Scatterv(hs.data(), counts.data(), displs.data(), mpiScalar<S>(), hd.data(), owned, mpiScalar<S>(), 0, group);
  Kokkos::deep_copy(dst, hd);
}

/// MPI_Gatherv onto the group's first member of `mine` (any trivially copyable T, sent as bytes);
/// the members' parts one after the other there, empty elsewhere.
template <class T>
std::vector<T> gatherOnFirst(MPI_Comm group, const std::vector<T>& mine) {
  int size = 1, rank = 0;
  MPI_Comm_size(group, &size);
  MPI_Comm_rank(group, &rank);
  int bytes = static_cast<int>(mine.size() * sizeof(T));
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size) + 1, 0);
  MPI_Gather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, group);
  for (int r = 0; r < size; ++r) displs[r + 1] = displs[r] + counts[r];
  std::vector<T> all(rank == 0 ? static_cast<std::size_t>(displs[size]) / sizeof(T) : 0);
  MPI_Gatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0, group);
  return all;
}

/// Coarsest-level gathers made by every DistributedAmg of this process (DistributedAmg::coarseGathers).
std::int64_t gCoarseGathers = 0;

}  // namespace

struct DistributedAmg::Impl {
  /// A level as the set-up builds it; after set-up only its sizes, halo, lambda_max and the
  /// vectors the coarsest solve or a double cycle shares are left (releaseSetupData).
  struct Level {
    HostCsr hA;
    std::vector<gid_t> gid;  ///< local -> global
    HaloPlan plan;
    std::unique_ptr<Halo> halo;
    CsrMatrix A, P, R;
    RealView invDiag, x, b, r, d;
    double lambdaMax = 1;
    LatticeRows lattice;  ///< this level's lattice (owned rows), when it is aggregated into cubes
    /// A level moved onto fewer ranks (agglomerateRows): its rows as the finer level's R and P see
    /// them (the layout it was built in) and how they travel to and from the ranks that hold it.
    struct Arrival {
      bool moved() const { return halo != nullptr; }
      GroupComm group;                  ///< the ranks whose rows one of them gathers (null: none)
      std::vector<int> counts, displs;  ///< rows per group member, on the group's first member
      lid_t owned = 0, local = 0;       ///< this rank's rows, and rows + ghosts, in that layout
      std::unique_ptr<Halo> halo;       ///< that layout's halo (the finer P's ghost columns); null: not moved
    } arrival;
  };
  /// A level in the cycle's precision S (S = double: the level's own matrices and vectors).
  template <class S>
  struct CycleLevel {
    CycleMat<S> A, P, R;
    SView<S> invDiag, x, b, r, d;
    SView<S> bArrive, xArrive;  ///< a moved level's b and x in the layout it was built in
  };

  MPI_Comm comm = MPI_COMM_NULL;  ///< null on one rank
  int ranks = 1, me = 0;
  /// Set-up: the ranks that may hold rows of the level being built are the multiples of stride
  /// (1 until a level moves onto fewer ranks).
  int stride = 1;
  bool coarseOnOneRank = false;  ///< the coarsest level is on one rank: its solve gathers nothing
  DistributedAmgOptions opt;
  HaloPlan finePlan;
  std::vector<gid_t> fineIds;
  std::vector<Level> levels;
  std::vector<CycleLevel<double>> cycleDouble;  ///< the cycle's levels (one of the two, by opt.mixedPrecision)
  std::vector<CycleLevel<float>> cycleFloat;
  std::vector<DistributedAmgLevelInfo> info;
  // Coarsest level, gathered on every rank.
  Kokkos::View<double**, MemSpace> coarseInv;  ///< owned rows x all rows (gathered order)
  RealView coarseAll, coarseOut;
  std::unique_ptr<DistributedAmg> coarseAmg;   ///< a large gathered level's one-process AMG
  std::vector<int> coarseCounts, coarseDispls;

  SolverComm solverComm(const Level& L) const { return SolverComm(comm, L.halo.get()); }

  std::int64_t globalCount(std::int64_t local) const {
    if (ranks == 1) return local;
    std::int64_t g = 0;
    MPI_Allreduce(&local, &g, 1, MPI_INT64_T, MPI_SUM, comm);
    return g;
  }

  /// `given`: the matrix level 0 was copied from (its row runs are reused).
  void finishLevel(const ExecSpace& exec, Level& L, std::size_t l, const CsrMatrix* given = nullptr) {
    const std::string label = "mfsi::kernels::damg::level" + std::to_string(l);
    L.A = toDevice(L.hA, label + "::A", true, given);
    L.halo = std::make_unique<Halo>(comm, L.plan);
    L.invDiag = RealView(label + "::invDiag", L.hA.nRows);
    invertDiagonal(exec, L.A, L.invDiag);
    for (RealView* v : {&L.x, &L.b, &L.r, &L.d}) *v = RealView(label + "::work", L.hA.nCols);
    // lambda_max(D^-1 A) by power iterations from a start vector fixed by the global ids.
    const SolverComm sc = solverComm(L);
    {
      auto h = Kokkos::create_mirror_view(L.x);
      for (lid_t i = 0; i < L.hA.nRows; ++i) h(i) = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(L.gid[i]));
      Kokkos::deep_copy(L.x, h);
    }
    double lambda = 1;
    for (int it = 0; it < 20; ++it) {
      L.halo->exchange(exec, L.x);
      blas::spmv(exec, L.A, L.x, L.r);
      scaled(exec, L.hA.nRows, 1.0, L.invDiag, L.r, L.r);
      const double nx = blas::norm2(exec, sc, L.hA.nRows, L.x), nr = blas::norm2(exec, sc, L.hA.nRows, L.r);
      if (!(nr > 0)) break;
      lambda = nr / nx;
      Kokkos::deep_copy(exec, L.x, L.r);  // x = D^-1 A x / |D^-1 A x|
      blas::axpby(exec, L.hA.nRows, 0.0, L.r, 1.0 / nr, L.x);
    }
    L.lambdaMax = 1.1 * lambda;
    DistributedAmgLevelInfo li;
    li.rows = globalCount(L.hA.nRows);
    li.nonzeros = globalCount(L.hA.ptr.back());
    li.ownedRows = L.hA.nRows;
    li.ghosts = L.hA.nCols - L.hA.nRows;
    li.ranks = static_cast<int>(globalCount(L.hA.nRows > 0 ? 1 : 0));
    info.push_back(li);
  }

  /// The next level of `L` (aggregation, P, R, A_c, its halo); false when L is the coarsest.
  bool coarsen(const ExecSpace& exec, std::size_t l) {
    Level& L = levels[l];
    const lid_t nOwned = L.hA.nRows, nLocal = L.hA.nCols;
    lid_t nAgg = 0;
    LatticeRows coarseLattice;
    const std::vector<lid_t> agg = L.lattice.valid()
                                       ? aggregateLattice(L.lattice, l == 0 ? 2 : 3, nAgg, coarseLattice)
                                       : aggregateOwned(L.hA, l == 0 ? opt.strengthThreshold : 0.0, nAgg);
    const std::int64_t rows = info[l].rows, coarseRows = globalCount(nAgg);
    if (coarseRows >= rows) return false;  // no coarsening: solve this level directly
    info[l].lattice = L.lattice.valid();

    // Global ids of the aggregates: contiguous per rank.
    std::vector<gid_t> start(ranks + 1, 0);
    {
      std::vector<long long> counts(ranks, nAgg);
      long long mine = nAgg;
      if (ranks > 1) MPI_Allgather(&mine, 1, MPI_LONG_LONG, counts.data(), 1, MPI_LONG_LONG, comm);
      for (int r = 0; r < ranks; ++r) start[r + 1] = start[r] + counts[r];
    }
    const gid_t first = start[me], last = start[me + 1];
    // The aggregate of every local fine entry (ghosts: from their owners).
    std::vector<gid_t> cg(nLocal);
    {
      auto h = Kokkos::create_mirror_view(L.r);
      for (lid_t i = 0; i < nOwned; ++i) h(i) = static_cast<double>(first + agg[i]);
      Kokkos::deep_copy(L.r, h);
      L.halo->exchange(exec, L.r);
      Kokkos::deep_copy(h, L.r);
      for (lid_t i = 0; i < nLocal; ++i) cg[i] = static_cast<gid_t>(std::llround(h(i)));
    }
    // Smoothed prolongator rows P = (I - omega D^-1 A) P_tent of the owned entries, then the
    // ghosts' rows from their owners.
    const double omega = opt.prolongationDamping / L.lambdaMax;
    GlobalRows pOwned;
    const std::vector<double> diag = diagonalOf(L.hA);
    for (lid_t i = 0; i < nOwned; ++i) {
      std::map<gid_t, double> row;
      const double di = diag[i];
      row[cg[i]] += 1.0;
      for (lid_t p = L.hA.ptr[i]; p < L.hA.ptr[i + 1]; ++p) row[cg[L.hA.col[p]]] -= omega * L.hA.val[p] / di;
      pOwned.push(Row(row.begin(), row.end()));
    }
    const GlobalRows pGhost = exchangeRows(comm, L.plan, pOwned);
    auto pRow = [&](lid_t j, auto&& f) {
      const GlobalRows& src = j < nOwned ? pOwned : pGhost;
      const lid_t k = j < nOwned ? j : j - nOwned;
      for (lid_t p = src.ptr[k]; p < src.ptr[k + 1]; ++p) f(src.col[p], src.val[p]);
    };
    // A P on the owned rows, then on the ghosts.
    GlobalRows bOwned;
    for (lid_t i = 0; i < nOwned; ++i) {
      std::map<gid_t, double> row;
      for (lid_t p = L.hA.ptr[i]; p < L.hA.ptr[i + 1]; ++p) {
        const double a = L.hA.val[p];
        pRow(L.hA.col[p], [&](gid_t c, double v) { row[c] += a * v; });
      }
      bOwned.push(Row(row.begin(), row.end()));
    }
    const GlobalRows bGhost = exchangeRows(comm, L.plan, bOwned);
    // R = P^T on the owned aggregates: every local fine entry's prolongator row that reaches one.
    std::vector<std::vector<std::pair<lid_t, double>>> rRows(nAgg);
    for (lid_t j = 0; j < nLocal; ++j)
      pRow(j, [&](gid_t c, double v) {
        if (c >= first && c < last) rRows[c - first].emplace_back(j, v);
      });
    // A_c = R (A P), rows of the owned aggregates, in a fixed order of summation.
    std::vector<std::map<gid_t, double>> acRows(nAgg);
    for (lid_t a = 0; a < nAgg; ++a)
      for (const auto& [j, rv] : rRows[a]) {
        const GlobalRows& src = j < nOwned ? bOwned : bGhost;
        const lid_t k = j < nOwned ? j : j - nOwned;
        for (lid_t p = src.ptr[k]; p < src.ptr[k + 1]; ++p) acRows[a][src.col[p]] += rv * src.val[p];
      }
    // Coarse ghosts: the other ranks' aggregates that A_c and P touch (their ids grow with their
    // owner, so sorting by id sorts by owner too).
    std::vector<gid_t> ghosts;
    for (const auto& row : acRows)
      for (const auto& [c, v] : row)
        if (c < first || c >= last) ghosts.push_back(c);
    for (gid_t c : pOwned.col)
      if (c < first || c >= last) ghosts.push_back(c);
    std::sort(ghosts.begin(), ghosts.end());
    ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
    std::vector<int> owner(ghosts.size());
    for (std::size_t g = 0; g < ghosts.size(); ++g)
      owner[g] = static_cast<int>(std::upper_bound(start.begin(), start.end(), ghosts[g]) - start.begin()) - 1;
    auto localOf = [&](gid_t c) -> lid_t {
      if (c >= first && c < last) return static_cast<lid_t>(c - first);
      return nAgg + static_cast<lid_t>(std::lower_bound(ghosts.begin(), ghosts.end(), c) - ghosts.begin());
    };
    const lid_t nCoarseLocal = nAgg + static_cast<lid_t>(ghosts.size());

    // Device P (owned fine rows x local coarse columns) and R (owned aggregates x local fine).
    HostCsr hP, hR, hAc;
    hP.nRows = nOwned;
    hP.nCols = nCoarseLocal;
    for (lid_t i = 0; i < nOwned; ++i) {
      std::vector<std::pair<lid_t, double>> row;
      pRow(i, [&](gid_t c, double v) { row.emplace_back(localOf(c), v); });
      std::sort(row.begin(), row.end());
      for (const auto& [c, v] : row) {
        hP.col.push_back(c);
        hP.val.push_back(v);
      }
      hP.ptr.push_back(static_cast<lid_t>(hP.col.size()));
    }
    hR.nRows = nAgg;
    hR.nCols = nLocal;
    hAc.nRows = nAgg;
    hAc.nCols = nCoarseLocal;
    for (lid_t a = 0; a < nAgg; ++a) {
      for (const auto& [j, v] : rRows[a]) {
        hR.col.push_back(j);
        hR.val.push_back(v);
      }
      hR.ptr.push_back(static_cast<lid_t>(hR.col.size()));
      std::vector<std::pair<lid_t, double>> row;
      for (const auto& [c, v] : acRows[a]) row.emplace_back(localOf(c), v);
      std::sort(row.begin(), row.end());
      for (const auto& [c, v] : row) {
        hAc.col.push_back(c);
        hAc.val.push_back(v);
      }
      hAc.ptr.push_back(static_cast<lid_t>(hAc.col.size()));
    }
    const std::string label = "mfsi::kernels::damg::level" + std::to_string(l);
    L.P = toDevice(hP, label + "::P");
    L.R = toDevice(hR, label + "::R");

    Level C;
    C.hA = std::move(hAc);
    C.gid.resize(nCoarseLocal);
    for (lid_t a = 0; a < nAgg; ++a) C.gid[a] = first + a;
    for (std::size_t g = 0; g < ghosts.size(); ++g) C.gid[nAgg + g] = ghosts[g];
    C.plan = planFromGhosts(comm, first, nAgg, ghosts, owner);
    C.lattice = std::move(coarseLattice);
    const int holding = (ranks + stride - 1) / stride;  // ranks that may hold rows of C
    if (opt.agglomerateRows > 0 && holding > 1 && coarseRows / holding < opt.agglomerateRows)
      levels.push_back(moveOntoFewerRanks(std::move(C), start, coarseRows, holding));
    else
      levels.push_back(std::move(C));
    finishLevel(exec, levels.back(), l + 1);
    return true;
  }

  /// Level C (rows: the aggregates of each rank, numbered by `start`) moved onto fewer ranks, about
  /// agglomerateRows rows each: the rows of each run of consecutive holding ranks onto the first of
  /// them, so every rank's ids stay one range. Collective.
  Level moveOntoFewerRanks(Level&& C, const std::vector<gid_t>& start, std::int64_t rows, int holding) {
    const int keep = static_cast<int>(std::max<std::int64_t>(1, rows / opt.agglomerateRows));
    const int newStride = stride * ((holding + keep - 1) / keep);
    const int first = (me / newStride) * newStride;  // the rank that takes this rank's rows
    const auto ownerOf = [&](gid_t id) {
      const int r = static_cast<int>(std::upper_bound(start.begin(), start.end(), id) - start.begin()) - 1;
      return (r / newStride) * newStride;
    };
    Level M;
    M.arrival.owned = C.hA.nRows;
    M.arrival.local = C.hA.nCols;
    M.arrival.halo = std::make_unique<Halo>(comm, C.plan);
    M.lattice.extent = C.lattice.extent;
    MPI_Comm group = MPI_COMM_NULL;
    MPI_Comm_split(comm, me % stride == 0 ? first : MPI_UNDEFINED, me, &group);
    M.arrival.group = GroupComm(group);
    std::vector<gid_t> ghosts;
    std::vector<int> ghostOwner;
    gid_t newFirst = 0;
    if (group != MPI_COMM_NULL) {
      // Each member's rows (length, global columns, values) and lattice cells, onto the first.
      const lid_t n = C.hA.nRows;
      std::vector<int> len(n);
      std::vector<gid_t> cols;
      for (lid_t i = 0; i < n; ++i) len[i] = C.hA.ptr[i + 1] - C.hA.ptr[i];
      for (lid_t c : C.hA.col) cols.push_back(C.gid[c]);
      const std::vector<int> allLen = gatherOnFirst(group, len);
      const std::vector<gid_t> allCols = gatherOnFirst(group, cols);
      const std::vector<double> allVals = gatherOnFirst(group, C.hA.val);
      const std::vector<std::array<std::int64_t, 3>> allAt = gatherOnFirst(group, C.lattice.at);
      const std::vector<int> counts = gatherOnFirst(group, std::vector<int>{n});
      if (me == first) {
        M.arrival.counts = counts;
        M.arrival.displs.assign(1, 0);
        for (int c : counts) M.arrival.displs.push_back(M.arrival.displs.back() + c);
        newFirst = start[first];
        const lid_t total = static_cast<lid_t>(allLen.size());
        const gid_t newLast = newFirst + total;
        for (gid_t c : allCols)
          if (c < newFirst || c >= newLast) ghosts.push_back(c);
        std::sort(ghosts.begin(), ghosts.end());
        ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
        for (gid_t g : ghosts) ghostOwner.push_back(ownerOf(g));
        auto localOf = [&](gid_t c) -> lid_t {
          if (c >= newFirst && c < newLast) return static_cast<lid_t>(c - newFirst);
          return total + static_cast<lid_t>(std::lower_bound(ghosts.begin(), ghosts.end(), c) - ghosts.begin());
        };
        M.hA.nRows = total;
        M.hA.nCols = total + static_cast<lid_t>(ghosts.size());
        std::size_t p = 0;
        for (lid_t i = 0; i < total; ++i) {
          std::vector<std::pair<lid_t, double>> row;
          for (int e = 0; e < allLen[i]; ++e, ++p) row.emplace_back(localOf(allCols[p]), allVals[p]);
          std::sort(row.begin(), row.end());
          for (const auto& [c, v] : row) {
            M.hA.col.push_back(c);
            M.hA.val.push_back(v);
          }
          M.hA.ptr.push_back(static_cast<lid_t>(M.hA.col.size()));
        }
        M.gid.resize(static_cast<std::size_t>(M.hA.nCols));
        for (lid_t i = 0; i < total; ++i) M.gid[i] = newFirst + i;
        for (std::size_t g = 0; g < ghosts.size(); ++g) M.gid[total + g] = ghosts[g];
        if (M.lattice.valid()) M.lattice.at = allAt;
      }
    }
    M.plan = planFromGhosts(comm, newFirst, M.hA.nRows, ghosts, ghostOwner);
    stride = newStride;
    return M;
  }

  /// Gather the last level onto every rank and invert it (pseudo-inverse: a singular Neumann
  /// operator keeps its null space out of the correction).
  void gatherCoarsest(const ExecSpace& exec) {
    const Level& L = levels.back();
    const lid_t n = L.hA.nRows;
    std::vector<long long> rowIds(L.gid.begin(), L.gid.begin() + n), colIds, allRows;
    std::vector<int> rowLen(n);
    std::vector<double> vals = L.hA.val;
    for (lid_t i = 0; i < n; ++i) rowLen[i] = L.hA.ptr[i + 1] - L.hA.ptr[i];
    for (lid_t c : L.hA.col) colIds.push_back(L.gid[c]);
    coarseCounts.assign(ranks, n);
    if (ranks > 1) MPI_Allgather(&n, 1, MPI_INT, coarseCounts.data(), 1, MPI_INT, comm);
    coarseDispls.assign(ranks + 1, 0);
    for (int r = 0; r < ranks; ++r) coarseDispls[r + 1] = coarseDispls[r] + coarseCounts[r];
    const int total = coarseDispls[ranks];
    allRows.resize(total);
    std::vector<int> allLen(total);
    if (ranks > 1) {
      MPI_Allgatherv(rowIds.data(), n, MPI_LONG_LONG, allRows.data(), coarseCounts.data(), coarseDispls.data(),
                     MPI_LONG_LONG, comm);
      MPI_Allgatherv(rowLen.data(), n, MPI_INT, allLen.data(), coarseCounts.data(), coarseDispls.data(), MPI_INT, comm);
    } else {
      allRows = rowIds;
      allLen = rowLen;
    }
    std::vector<int> nnzCounts(ranks, 0), nnzDispls(ranks + 1, 0);
    for (int r = 0; r < ranks; ++r) {
      for (int k = coarseDispls[r]; k < coarseDispls[r + 1]; ++k) nnzCounts[r] += allLen[k];
      nnzDispls[r + 1] = nnzDispls[r] + nnzCounts[r];
    }
    std::vector<long long> allCols(nnzDispls[ranks]);
    std::vector<double> allVals(nnzDispls[ranks]);
    if (ranks > 1) {
      MPI_Allgatherv(colIds.data(), static_cast<int>(colIds.size()), MPI_LONG_LONG, allCols.data(), nnzCounts.data(),
                     nnzDispls.data(), MPI_LONG_LONG, comm);
      MPI_Allgatherv(vals.data(), static_cast<int>(vals.size()), MPI_DOUBLE, allVals.data(), nnzCounts.data(),
                     nnzDispls.data(), MPI_DOUBLE, comm);
    } else {
      allCols = colIds;
      allVals = vals;
    }
    // The gathered level as one process's matrix, rows and columns in gathered order (rank by
    // rank, each rank's rows in its order).
    std::map<long long, int> where;
    for (int k = 0; k < total; ++k) where[allRows[k]] = k;
    HostCsr g;
    g.nRows = g.nCols = total;
    for (int k = 0, p = 0; k < total; ++k) {
      std::map<int, double> row;
      for (int e = 0; e < allLen[k]; ++e, ++p) {
        const auto it = where.find(allCols[p]);
        MFSI_CHECK(it != where.end(), "distributed AMG: coarsest column " << allCols[p] << " has no row");
        row[it->second] += allVals[p];
      }
      for (const auto& [c, v] : row) {
        g.col.push_back(c);
        g.val.push_back(v);
      }
      g.ptr.push_back(static_cast<lid_t>(g.col.size()));
    }
    coarseAll = RealView("mfsi::kernels::damg::coarseAll", total);
    coarseAmg.reset();
    coarseOnOneRank = std::count_if(coarseCounts.begin(), coarseCounts.end(), [](int c) { return c > 0; }) <= 1;
    if (coarseOnOneRank && n == 0) {  // another rank holds the whole level
      coarseInv = Kokkos::View<double**, MemSpace>("mfsi::kernels::damg::coarseInverse", 0, total);
      return;
    }
    if (ranks > 1 && total > opt.denseCoarseRows) {
      gatheredAmg(exec, g, allRows);
      return;
    }
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(total, total);
    for (int k = 0; k < total; ++k)
      for (lid_t p = g.ptr[k]; p < g.ptr[k + 1]; ++p) M(k, g.col[p]) = g.val[p];
    const Eigen::MatrixXd S = 0.5 * (M + M.transpose());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
    const Eigen::VectorXd lam = eig.eigenvalues();
    const double cut = 1e-10 * lam.cwiseAbs().maxCoeff();
    Eigen::VectorXd inv(total);
    for (int k = 0; k < total; ++k) inv(k) = std::abs(lam(k)) > cut ? 1.0 / lam(k) : 0.0;
    const Eigen::MatrixXd Pinv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
    coarseInv = Kokkos::View<double**, MemSpace>("mfsi::kernels::damg::coarseInverse", n, total);
    auto h = Kokkos::create_mirror_view(coarseInv);
    for (lid_t i = 0; i < n; ++i)
      for (int k = 0; k < total; ++k) h(i, k) = Pinv(coarseDispls[me] + i, k);
    Kokkos::deep_copy(coarseInv, h);
  }

  /// The gathered level `g` (every row owned, no ghosts; global ids `allRows`) and its AMG, whose
  /// own coarsest level is dense.
  void gatheredAmg(const ExecSpace& exec, const HostCsr& g, const std::vector<long long>& allRows) {
    const int total = g.nRows;
    HaloPlan plan;
    plan.nOwned = plan.nLocal = total;
    plan.sendOffsets = plan.recvOffsets = {0};
    DistributedAmgOptions o = opt;
    o.coarseSize = std::min(opt.coarseSize, opt.denseCoarseRows);
    o.denseCoarseRows = std::numeric_limits<std::int64_t>::max();
    coarseAmg = std::make_unique<DistributedAmg>(MPI_COMM_NULL, plan, std::vector<gid_t>(allRows.begin(), allRows.end()), o);
    coarseAmg->setup(exec, toDevice(g, "mfsi::kernels::damg::gathered"));
    coarseOut = RealView("mfsi::kernels::damg::coarseOut", total);
  }

  void coarseSolve(const ExecSpace& exec, Level& L) {
    const lid_t n = L.hA.nRows;
    if (coarseOnOneRank && n == 0) return;  // the rank that holds the level solves it alone
    if (ranks == 1 || coarseOnOneRank) {
      Kokkos::deep_copy(exec, Kokkos::subview(coarseAll, std::make_pair(0, n)), Kokkos::subview(L.b, std::make_pair(0, n)));
    } else {
      auto hb = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(L.b, std::make_pair(0, n)));
      auto ha = Kokkos::create_mirror_view(coarseAll);
      MPI_Allgatherv(hb.data(), n, MPI_DOUBLE, ha.data(), coarseCounts.data(), coarseDispls.data(), MPI_DOUBLE, comm);
      ++gCoarseGathers;
      Kokkos::deep_copy(exec, coarseAll, ha);
    }
    if (coarseAmg) {
      coarseAmg->apply(exec, coarseAll, coarseOut);
      const int first = coarseDispls[me];
      Kokkos::deep_copy(exec, Kokkos::subview(L.x, std::make_pair(0, n)),
                        Kokkos::subview(coarseOut, std::make_pair(first, first + n)));
    } else {
      denseRows(exec, coarseInv, coarseAll, L.x);
    }
  }

  /// The cycle's levels in precision S: the operators (float: rounded copies sharing the
  /// sparsity and row runs), inverse diagonals and work vectors. The coarsest level, solved in
  /// double from its level's own b into its x, holds only its right-hand side and solution.
  template <class S>
  void buildCycle(const ExecSpace& exec, std::vector<CycleLevel<S>>& cycle) {
    cycle.clear();
    for (std::size_t l = 0; l < levels.size(); ++l) {
      Level& L = levels[l];
      const bool coarsest = l + 1 == levels.size();
      CycleLevel<S> C;
      const std::string label = "mfsi::kernels::damg::level" + std::to_string(l);
      if constexpr (std::is_same<S, double>::value) {
        C.x = L.x;
        C.b = L.b;
        if (!coarsest) {
          C.invDiag = L.invDiag;
          C.r = L.r;
          C.d = L.d;
        }
      } else {
        for (SView<S>* v : {&C.x, &C.b}) *v = SView<S>(label + "::work::float", L.hA.nCols);
        if (!coarsest) {
          C.invDiag = SView<S>(label + "::invDiag::float", L.hA.nRows);
          convert<S>(exec, L.hA.nRows, L.invDiag, C.invDiag);
          for (SView<S>* v : {&C.r, &C.d}) *v = SView<S>(label + "::work::float", L.hA.nCols);
        }
      }
      if (!coarsest) {
        C.A = cycleMat<S>(exec, L.A);
        C.P = cycleMat<S>(exec, L.P);
        C.R = cycleMat<S>(exec, L.R);
        // The products' ghost columns: A's and R's those of this level, P's those of the next
        // level (or of its arrival layout, when it has moved onto fewer ranks).
        const Level& next = levels[l + 1];
        splitByGhosts(C.A, L.halo.get(), label + "::A");
        splitByGhosts(C.R, L.halo.get(), label + "::R");
        splitByGhosts(C.P, next.arrival.moved() ? next.arrival.halo.get() : next.halo.get(), label + "::P");
      }
      if (L.arrival.moved())
        for (SView<S>* v : {&C.bArrive, &C.xArrive}) *v = SView<S>(label + "::arrival", L.arrival.local);
      cycle.push_back(std::move(C));
    }
  }

  /// M's ghost split (CsrGhostSplit), whose ghost columns are those of `halo`, when the cycle
  /// overlaps its exchanges and the halo has neighbours.
  template <class S>
  void splitByGhosts(CycleMat<S>& M, const Halo* halo, const std::string& label) const {
    if (opt.overlapExchange && halo != nullptr && halo->neighbours() > 0)
      M.split = buildGhostSplit(M.nRows, halo->nOwned(), M.rowPtr, M.colIdx, M.runs, label);
  }

  /// After set-up, drop what only the set-up uses: the host copies of the levels, their global
  /// ids and lattices, the level matrices, inverse diagonals and smoothing vectors (the cycle
  /// holds those it uses), and under a float cycle the double b and x of every level but the
  /// coarsest (its solve is in double). The next set-up builds every level again.
  void releaseSetupData() {
    for (std::size_t l = 0; l < levels.size(); ++l) {
      Level& L = levels[l];
      std::vector<lid_t>().swap(L.hA.ptr);
      std::vector<lid_t>().swap(L.hA.col);
      std::vector<double>().swap(L.hA.val);
      std::vector<gid_t>().swap(L.gid);
      L.lattice = LatticeRows{};
      L.A = CsrMatrix{};
      L.P = CsrMatrix{};
      L.R = CsrMatrix{};
      L.invDiag = L.r = L.d = RealView();
      if (opt.mixedPrecision && l + 1 < levels.size()) L.x = L.b = RealView();
    }
  }

  std::size_t memoryBytes() const {
    ByteCount c;
    c.vector(fineIds);
    for (const Level& L : levels) {
      c.vector(L.hA.ptr);
      c.vector(L.hA.col);
      c.vector(L.hA.val);
      c.vector(L.gid);
      c.vector(L.lattice.at);
      for (const CsrMatrix* M : {&L.A, &L.P, &L.R}) c.csr(*M);
      for (const RealView* v : {&L.invDiag, &L.x, &L.b, &L.r, &L.d}) c.view(*v);
    }
    count(c, cycleDouble);
    count(c, cycleFloat);
    c.view(coarseInv);
    c.view(coarseAll);
    c.view(coarseOut);
    return c.bytes + (coarseAmg ? coarseAmg->memoryBytes() : 0);
  }

  template <class S>
  static void count(ByteCount& c, const std::vector<CycleLevel<S>>& cycle) {
    for (const CycleLevel<S>& C : cycle) {
      for (const CycleMat<S>* M : {&C.A, &C.P, &C.R}) c.csr(*M);
      for (const SView<S>* v : {&C.invDiag, &C.x, &C.b, &C.r, &C.d, &C.bArrive, &C.xArrive}) c.view(*v);
    }
  }

  /// Fourth-kind Chebyshev smoothing in D^-1 A on [0, lambda_max] (Lottes 2023, as kernels/Amg):
  /// d_0 = 4 / (3 rho) D^-1 r_0, d_k = (2k - 1) / (2k + 3) d_{k-1} + (8k + 4) / ((2k + 3) rho) D^-1 r_k.
  /// `fromZeroX`: x is 0 (the pre-smoothing of a V-cycle), so r_0 = b needs no product.
  template <class S>
  void chebyshev(const ExecSpace& exec, const Level& L, CycleLevel<S>& C, bool fromZeroX) {
    const lid_t n = L.hA.nRows;
    const double rho = L.lambdaMax;
    const S c0 = static_cast<S>(4.0 / (3.0 * rho));
    if (fromZeroX) {
      fromZero<S>(exec, n, c0, C.invDiag, C.b, C.r, C.d);
    } else {
      exchangeAndMultiply<S>(exec, *L.halo, 1, C.A, C.x, 0, C.r);
      fromProduct<S>(exec, n, C.b, C.r);
      scaled<S>(exec, n, c0, C.invDiag, C.r, C.d);
    }
    for (int k = 1; k <= opt.chebyshevDegree; ++k) {
      addTo<S>(exec, n, C.d, C.x);
      if (k == opt.chebyshevDegree) break;
      exchangeAndMultiply<S>(exec, *L.halo, -1, C.A, C.d, 1, C.r);
      chebyshevDirection<S>(exec, n, static_cast<S>((2.0 * k - 1.0) / (2.0 * k + 3.0)),
                            static_cast<S>((8.0 * k + 4.0) / ((2.0 * k + 3.0) * rho)), C.invDiag, C.r, C.d);
    }
  }

  template <class S>
  void cycle(const ExecSpace& exec, std::vector<CycleLevel<S>>& cyc, std::size_t l) {
    Level& L = levels[l];
    CycleLevel<S>& C = cyc[l];
    const lid_t n = L.hA.nRows;
    if (l + 1 == levels.size()) {  // the coarsest solve, in double
      if constexpr (!std::is_same<S, double>::value) convert<double>(exec, n, C.b, L.b);
      coarseSolve(exec, L);
      if constexpr (!std::is_same<S, double>::value) convert<S>(exec, n, L.x, C.x);
      return;
    }
    Kokkos::deep_copy(exec, C.x, S(0));
    chebyshev(exec, L, C, true);
    exchangeAndMultiply<S>(exec, *L.halo, 1, C.A, C.x, 0, C.r);
    fromProduct<S>(exec, n, C.b, C.r);
    CycleLevel<S>& N = cyc[l + 1];
    const typename Level::Arrival& a = levels[l + 1].arrival;
    if (!a.moved()) {
      exchangeAndMultiply<S>(exec, *L.halo, 1, C.R, C.r, 0, N.b);
      cycle(exec, cyc, l + 1);
      exchangeAndMultiply<S>(exec, *levels[l + 1].halo, 1, C.P, N.x, 1, C.x);
    } else {  // the next level lives on fewer ranks: its b goes there, its x comes back
      exchangeAndMultiply<S>(exec, *L.halo, 1, C.R, C.r, 0, N.bArrive);
      if (a.group.get() != MPI_COMM_NULL)
        gatherToFirst<S>(exec, a.group.get(), a.counts, a.displs, a.owned, N.bArrive, N.b);
      cycle(exec, cyc, l + 1);
      if (a.group.get() != MPI_COMM_NULL)
        scatterFromFirst<S>(exec, a.group.get(), a.counts, a.displs, a.owned, N.x, N.xArrive);
      exchangeAndMultiply<S>(exec, *a.halo, 1, C.P, N.xArrive, 1, C.x);
    }
    chebyshev(exec, L, C, false);
  }
};

DistributedAmg::DistributedAmg(MPI_Comm comm, const HaloPlan& plan, std::vector<gid_t> globalIds,
                               const DistributedAmgOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->ranks = commSize(comm);
  impl_->me = commRank(comm);
  impl_->comm = impl_->ranks > 1 ? comm : MPI_COMM_NULL;
  impl_->opt = options;
  impl_->finePlan = plan;
  impl_->fineIds = std::move(globalIds);
  MFSI_CHECK(static_cast<lid_t>(impl_->fineIds.size()) == plan.nLocal,
             "distributed AMG: " << impl_->fineIds.size() << " global ids for " << plan.nLocal << " columns");
  MFSI_CHECK(options.chebyshevDegree >= 1 && options.coarseSize >= 1 && options.maxLevels >= 1,
             "distributed AMG: chebyshevDegree, coarseSize and maxLevels must be >= 1");
}

DistributedAmg::~DistributedAmg() = default;

std::int64_t DistributedAmg::coarseGathers() { return gCoarseGathers; }

const std::vector<DistributedAmgLevelInfo>& DistributedAmg::levels() const { return impl_->info; }

void DistributedAmg::setup(const ExecSpace& exec, const CsrMatrix& A) {
  Impl& m = *impl_;
  MFSI_CHECK(A.nRows == m.finePlan.nOwned && A.nCols == m.finePlan.nLocal,
             "distributed AMG: a " << A.nRows << " x " << A.nCols << " matrix for a halo of " << m.finePlan.nOwned
                                   << " owned and " << m.finePlan.nLocal << " local entries");
  m.levels.clear();
  m.info.clear();
  m.stride = 1;
  Impl::Level L0;
  L0.hA = hostCopy(A);
  L0.gid = m.fineIds;
  L0.plan = m.finePlan;
  m.levels.push_back(std::move(L0));
  m.finishLevel(exec, m.levels.back(), 0, &A);
  if (m.opt.latticeAggregation) {
    Impl::Level& F = m.levels.front();
    // The diagonal of every owned row and ghost (the ghosts' from their owners).
    auto hd = Kokkos::create_mirror_view(F.r);
    const std::vector<double> owned = diagonalOf(F.hA);
    for (lid_t i = 0; i < F.hA.nRows; ++i) hd(i) = owned[i];
    Kokkos::deep_copy(F.r, hd);
    F.halo->exchange(exec, F.r);
    Kokkos::deep_copy(hd, F.r);
    const std::vector<double> diagonal(hd.data(), hd.data() + F.hA.nCols);
    F.lattice = detectLattice(m.comm, F.hA, F.gid, m.info.front().rows, m.opt.strengthThreshold, diagonal);
  }
  while (static_cast<int>(m.levels.size()) < m.opt.maxLevels && m.info.back().rows > m.opt.coarseSize)
    if (!m.coarsen(exec, m.levels.size() - 1)) break;
  // One rank inverts its coarsest level densely; several gather it onto every rank.
  MFSI_CHECK(m.info.back().rows <= (m.ranks > 1 ? 4000000 : 20000),
             "distributed AMG: the coarsest level still has "
                                              << m.info.back().rows << " rows (raise maxLevels)");
  m.gatherCoarsest(exec);
  m.cycleDouble.clear();
  m.cycleFloat.clear();
  if (m.opt.mixedPrecision)
    m.buildCycle(exec, m.cycleFloat);
  else
    m.buildCycle(exec, m.cycleDouble);
  m.releaseSetupData();
}

std::size_t DistributedAmg::memoryBytes() const { return impl_->memoryBytes(); }

void DistributedAmg::apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) {
  Impl& m = *impl_;
  MFSI_CHECK(!m.levels.empty(), "distributed AMG: apply before setup");
  const lid_t n = m.levels.front().hA.nRows;
  if (m.opt.mixedPrecision) {
    convert<float>(exec, n, r, m.cycleFloat.front().b);
    m.cycle(exec, m.cycleFloat, 0);
    convert<double>(exec, n, m.cycleFloat.front().x, z);
  } else {
    Impl::Level& L = m.levels.front();
    Kokkos::deep_copy(exec, Kokkos::subview(L.b, std::make_pair(0, n)), Kokkos::subview(r, std::make_pair(0, n)));
    m.cycle(exec, m.cycleDouble, 0);
    Kokkos::deep_copy(exec, Kokkos::subview(z, std::make_pair(0, n)), Kokkos::subview(L.x, std::make_pair(0, n)));
  }
}

}  // namespace mfsi
