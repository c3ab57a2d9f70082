#pragma once
/// \file
/// \brief Halo exchange: the owners' values copied into the ghosts of every neighbour rank.
///
/// Pack and unpack are Kokkos kernels over one contiguous buffer per direction; the messages are
/// persistent MPI requests (created at the first exchange, reused after), staged through host
/// mirrors of the buffers (a no-op on host memory spaces; a device build copies, which a
/// device-aware MPI would spare). Received values land in the ghost ranges directly from the
/// buffer, since ghosts are grouped by owner (core/parallel/LocalMesh). An exchange is
/// deterministic: each value is a copy, never a sum.
#include "core/Types.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <mpi.h>

#include <cstdint>
#include <vector>

namespace mfsi {

/// \brief What a solver on one rank's part of a decomposed mesh needs to reach the other ranks:
/// their communicator and the part's halo plans (core/parallel/LocalMesh). The default (no
/// communicator) is a whole mesh on one rank.
struct RankDomain {
  MPI_Comm comm = MPI_COMM_NULL;
  HaloPlan cells;
  HaloPlan nodes;
  gid_t incompleteNode = -1;  ///< LocalMeshPart::incompleteNode
  bool distributed() const { return comm != MPI_COMM_NULL; }
};

/// \brief One kind of entity's halo on one rank. Not copyable (it owns MPI requests).
class Halo {
 public:
  /// No neighbours: exchanges do nothing.
  Halo() = default;
  Halo(MPI_Comm comm, const HaloPlan& plan);
  ~Halo();
  Halo(const Halo&) = delete;
  Halo& operator=(const Halo&) = delete;

  /// \brief Ghost entries [nOwned, nLocal) of `x` <- their owners' values.
  void exchange(const ExecSpace& exec, const RealView& x) const;
  /// \brief The same for a float field (sent as doubles: a float cycle's halo, kernels/DistributedAmg).
  void exchange(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const;
  /// \brief The same for the three columns of an n x 3 field, in one message per neighbour.
  void exchange(const ExecSpace& exec, const Real3View& x) const;
  /// \brief The same for the nine entries of an n x 3 x 3 field (a gradient of a vector).
  void exchange(const ExecSpace& exec, const Kokkos::View<real* [3][3], MemSpace>& x) const;

  /// \brief An exchange of a one-column field in two halves, so that work which reads no ghost can
  /// run while the messages are under way: `begin` packs the owners' values and starts the
  /// messages; `end` waits for them and writes the ghosts. Between the two, neither the owned
  /// entries that are sent nor the ghosts of `x` may be written, the ghosts not read, and no other
  /// exchange of this halo begun. begin + end is `exchange`, bit for bit.
  void begin(const ExecSpace& exec, const RealView& x) const;
  void begin(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const;
  void end(const ExecSpace& exec, const RealView& x) const;
  void end(const ExecSpace& exec, const Kokkos::View<float*, MemSpace>& x) const;

  /// \brief The exchanges above: pack and start, then finish and unpack, a field of K columns
  /// (View: K = 1, 3 or 9). Public only because nvcc compiles extended device lambdas solely in
  /// public members.
  template <int K, class View>
  void beginColumns(const ExecSpace& exec, const View& x) const;
  template <int K, class View>
  void endColumns(const ExecSpace& exec, const View& x) const;
  template <int K, class View>
  void exchangeColumns(const ExecSpace& exec, const View& x) const;

  int neighbours() const { return static_cast<int>(neighbours_.size()); }
  lid_t nOwned() const { return nOwned_; }
  lid_t nLocal() const { return nLocal_; }
  /// \brief Values sent by this rank per exchange of `components` columns, in bytes.
  std::int64_t sendBytes(int components) const;
  /// \brief Messages sent by this rank per exchange (empty ones are not sent).
  int sendMessages() const;
  /// \brief Bytes and messages this rank has sent in all exchanges so far.
  std::int64_t bytesSent() const { return bytesSent_; }
  std::int64_t messagesSent() const { return messagesSent_; }
  /// \brief The same summed over every halo of this process (the fluid's cells, the AMG's
  /// levels), and the number of exchanges made.
  static std::int64_t allBytesSent();
  static std::int64_t allMessagesSent();
  static std::int64_t allExchanges();
  /// \brief Of those, the exchanges made in two halves (`begin` and `end`) with neighbours.
  static std::int64_t allSplitExchanges();
  /// \brief Wall seconds this process has spent in starting its halos' messages and waiting for
  /// their completion: the transfer itself and any wait for a neighbour still computing; with work
  /// between `begin` and `end`, what that work did not hide.
  static double allTransferSeconds();

 private:
  /// Send buffer filled (device): copy it to the host and start the messages.
  void start(const ExecSpace& exec, int components) const;
  /// Wait for the messages and copy what arrived into the receive buffer (device).
  void finish(const ExecSpace& exec, int components) const;

  MPI_Comm comm_ = MPI_COMM_NULL;
  std::vector<int> neighbours_;
  std::vector<lid_t> sendOffsets_, recvOffsets_;
  IndexView sendIndices_;
  lid_t nOwned_ = 0, nLocal_ = 0;
  RealView sendBuf_, recvBuf_;
  RealView::HostMirror sendHost_, recvHost_;
  mutable std::int64_t bytesSent_ = 0, messagesSent_ = 0;
  mutable std::vector<MPI_Request> requests_[3];  ///< persistent: [0] one column, [1] three, [2] nine
  mutable int inFlight_ = 0;                      ///< columns of the exchange begun and not ended; 0: none
};

}  // namespace mfsi
