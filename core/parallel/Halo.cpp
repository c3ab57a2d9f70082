#include "core/parallel/Halo.hpp"

#include "core/Error.hpp"

namespace mfsi {

namespace {
constexpr int kHaloTag = 7411;
std::int64_t gBytes = 0, gMessages = 0, gExchanges = 0, gSplitExchanges = 0;
double gWaitSeconds = 0;
static_assert(sizeof(real) == sizeof(double), "the halo sends reals as MPI_DOUBLE");
}  // namespace

Halo::Halo(MPI_Comm comm, const HaloPlan& plan)
    : comm_(comm),
      neighbours_(plan.neighbours),
      sendOffsets_(plan.sendOffsets),
      recvOffsets_(plan.recvOffsets),
      nOwned_(plan.nOwned),
      nLocal_(plan.nLocal) {
  MFSI_CHECK(sendOffsets_.size() == neighbours_.size() + 1 && recvOffsets_.size() == neighbours_.size() + 1,
             "halo: inconsistent plan (" << neighbours_.size() << " neighbours)");
  MFSI_CHECK(nOwned_ + recvOffsets_.back() == nLocal_,
             "halo: " << nOwned_ << " owned + " << recvOffsets_.back() << " ghosts != " << nLocal_ << " entries");
  const lid_t nSend = sendOffsets_.back(), nRecv = recvOffsets_.back();
  sendIndices_ = IndexView("mfsi::core::halo::sendIndices", nSend);
  {
    auto h = Kokkos::create_mirror_view(sendIndices_);
    for (lid_t i = 0; i < nSend; ++i) h(i) = plan.sendIndices[i];
    Kokkos::deep_copy(sendIndices_, h);
  }
  sendBuf_ = RealView("mfsi::core::halo::sendBuffer", 9 * static_cast<std::size_t>(nSend));
  recvBuf_ = RealView("mfsi::core::halo::recvBuffer", 9 * static_cast<std::size_t>(nRecv));
  sendHost_ = Kokkos::create_mirror_view(sendBuf_);
  recvHost_ = Kokkos::create_mirror_view(recvBuf_);
}

Halo::~Halo() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return;
  for (auto& list : requests_)
    for (auto& r : list)
      if (r != MPI_REQUEST_NULL) MPI_Request_free(&r);
}

std::int64_t Halo::allBytesSent() { return gBytes; }
std::int64_t Halo::allMessagesSent() { return gMessages; }
std::int64_t Halo::allExchanges() { return gExchanges; }
std::int64_t Halo::allSplitExchanges() { return gSplitExchanges; }
double Halo::allTransferSeconds() { return gWaitSeconds; }

std::int64_t Halo::sendBytes(int components) const {
  return static_cast<std::int64_t>(sendOffsets_.empty() ? 0 : sendOffsets_.back()) * components *
         static_cast<std::int64_t>(sizeof(real));
}

int Halo::sendMessages() const {
  int n = 0;
  for (std::size_t k = 0; k < neighbours_.size(); ++k) n += sendOffsets_[k + 1] > sendOffsets_[k] ? 1 : 0;
  return n;
}

namespace {
int requestSet(int components) { return components == 1 ? 0 : components == 3 ? 1 : 2; }
}  // namespace

void Halo::start(const ExecSpace& exec, int components) const {
  Kokkos::deep_copy(exec, sendHost_, sendBuf_);
  exec.fence();
  auto& reqs = requests_[requestSet(components)];
  if (reqs.empty()) {
    // Persistent requests on the (fixed) host buffers; a column count picks the message length.
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      const int nr = (recvOffsets_[k + 1] - recvOffsets_[k]) * components;
      const int ns = (sendOffsets_[k + 1] - sendOffsets_[k]) * components;
      MPI_Request r;
      if (nr > 0) {
        MPI_Recv_init(recvHost_.data() + recvOffsets_[k] * components, nr, MPI_DOUBLE, neighbours_[k], kHaloTag,
                      comm_, &r);
        reqs.push_back(r);
      }
      if (ns > 0) {
        MPI_Send_init(sendHost_.data() + sendOffsets_[k] * components, ns, MPI_DOUBLE, neighbours_[k], kHaloTag,
                      comm_, &r);
        reqs.push_back(r);
      }
    }
  }
  const double t0 = MPI_Wtime();
  if (!reqs.empty()) MPI_Startall(static_cast<int>(reqs.size()), reqs.data());
  gWaitSeconds += MPI_Wtime() - t0;
  inFlight_ = components;
}

void Halo::finish(const ExecSpace& exec, int components) const {
  MFSI_CHECK(inFlight_ == components, "halo: an exchange of " << components << " columns ended while "
                                                              << (inFlight_ == 0 ? "none" : "another") << " was begun");
  auto& reqs = requests_[requestSet(components)];
  const double t0 = MPI_Wtime();
  if (!reqs.empty()) MPI_Waitall(static_cast<int>(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  gWaitSeconds += MPI_Wtime() - t0;
  inFlight_ = 0;
  bytesSent_ += sendBytes(components);
  messagesSent_ += sendMessages();
  gBytes += sendBytes(components);
  gMessages += sendMessages();
  ++gExchanges;
  Kokkos::deep_copy(exec, recvBuf_, recvHost_);
}

namespace {
// Entry k of row i of a field with K columns, for the pack and unpack kernels.
KOKKOS_INLINE_FUNCTION real& entry(const RealView& x, lid_t i, int) { return x(i); }
KOKKOS_INLINE_FUNCTION float& entry(const Kokkos::View<float*, MemSpace>& x, lid_t i, int) { return x(i); }
KOKKOS_INLINE_FUNCTION real& entry(const Real3View& x, lid_t i, int k) { return x(i, k); }
KOKKOS_INLINE_FUNCTION real& entry(const Kokkos::View<real* [3][3], MemSpace>& x, lid_t i, int k) {
  return x(i, k / 3, k % 3);
}
}  // namespace

template <int K, class View>
void Halo::beginColumns(const ExecSpace& exec, const View& x) const {
  if (neighbours_.empty()) return;
  // Before the pack: the buffer of an exchange under way is still being sent.
  MFSI_CHECK(inFlight_ == 0, "halo: an exchange of field '" << x.label() << "' begun while one of " << inFlight_
                                                           << " column(s) is still under way");
  MFSI_CHECK(static_cast<lid_t>(x.extent(0)) >= nLocal_,
             "halo: field '" << x.label() << "' has " << x.extent(0) << " entries, the halo " << nLocal_);
  const lid_t nSend = sendOffsets_.back();
  auto idx = sendIndices_;
  auto buf = sendBuf_;
  Kokkos::parallel_for(
      "mfsi::core::halo::pack", RangePolicy(exec, 0, nSend), KOKKOS_LAMBDA(lid_t i) {
        for (int k = 0; k < K; ++k) buf(K * i + k) = entry(x, idx(i), k);
      });
  start(exec, K);
}

template <int K, class View>
void Halo::endColumns(const ExecSpace& exec, const View& x) const {
  if (neighbours_.empty()) return;
  finish(exec, K);
  const lid_t nRecv = recvOffsets_.back(), base = nOwned_;
  auto rb = recvBuf_;
  Kokkos::parallel_for(
      "mfsi::core::halo::unpack", RangePolicy(exec, 0, nRecv), KOKKOS_LAMBDA(lid_t i) {
        for (int k = 0; k < K; ++k) entry(x, base + i, k) = rb(K * i + k);
      });
}

template <int K, class View>
void Halo::exchangeColumns(const ExecSpace& exec, const View& x) const {
  beginColumns<K>(exec, x);
  endColumns<K>(exec, x);
}

void Halo::begin(const ExecSpace& exec, const RealView& x) const {
  if (!neighbours_.empty()) ++gSplitExchanges;
  beginColumns<1>(exec, x);
}

void Halo::begin(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const {
  if (!neighbours_.empty()) ++gSplitExchanges;
  beginColumns<1>(exec, x);
}

void Halo::end(const ExecSpace& exec, const RealView& x) const { endColumns<1>(exec, x); }

void Halo::end(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const { endColumns<1>(exec, x); }

void Halo::exchange(const ExecSpace& exec, const RealView& x) const { exchangeColumns<1>(exec, x); }

void Halo::exchange(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const {
  exchangeColumns<1>(exec, x);
}

void Halo::exchange(const ExecSpace& exec, const Real3View& x) const { exchangeColumns<3>(exec, x); }

void Halo::exchange(const ExecSpace& exec, const Kokkos::View<real* [3][3], MemSpace>& x) const {
  exchangeColumns<9>(exec, x);
}

}  // namespace mfsi
