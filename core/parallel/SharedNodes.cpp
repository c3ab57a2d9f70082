#include "core/parallel/SharedNodes.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <numeric>

namespace mfsi {

namespace {

constexpr int kFoldTag = 7301;
constexpr int kCopyTag = 7302;

/// Sends `send[k]` to plan.neighbours[k] and receives `recv[k]` (sized by the caller) from it.
void swapWithNeighbours(MPI_Comm comm, const HaloPlan& plan, int tag, const std::vector<std::vector<double>>& send,
                        std::vector<std::vector<double>>& recv) {
  std::vector<MPI_Request> requests;
  requests.reserve(2 * plan.neighbours.size());
  for (std::size_t k = 0; k < plan.neighbours.size(); ++k) {
    requests.emplace_back();
    MPI_Irecv(recv[k].data(), static_cast<int>(recv[k].size()), MPI_DOUBLE, plan.neighbours[k], tag, comm,
              &requests.back());
  }
  for (std::size_t k = 0; k < plan.neighbours.size(); ++k) {
    requests.emplace_back();
    MPI_Isend(send[k].data(), static_cast<int>(send[k].size()), MPI_DOUBLE, plan.neighbours[k], tag, comm,
              &requests.back());
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
}

}  // namespace

void foldGhostsIntoOwners(MPI_Comm comm, const HaloPlan& plan, int components, const std::vector<double>& values,
                          const std::function<void(lid_t, const double*)>& fold) {
  const std::size_t c = static_cast<std::size_t>(components);
  MFSI_CHECK(values.size() == static_cast<std::size_t>(plan.nLocal) * c,
             "fold into owners: " << values.size() << " values for " << plan.nLocal << " entries of " << components);
  const std::size_t nb = plan.neighbours.size();
  std::vector<std::vector<double>> send(nb), recv(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    const std::size_t first = static_cast<std::size_t>(plan.nOwned + plan.recvOffsets[k]);
    const std::size_t last = static_cast<std::size_t>(plan.nOwned + plan.recvOffsets[k + 1]);
    send[k].assign(values.begin() + first * c, values.begin() + last * c);
    recv[k].resize(static_cast<std::size_t>(plan.sendOffsets[k + 1] - plan.sendOffsets[k]) * c);
  }
  swapWithNeighbours(comm, plan, kFoldTag, send, recv);
  for (std::size_t k = 0; k < nb; ++k)
    for (lid_t j = plan.sendOffsets[k]; j < plan.sendOffsets[k + 1]; ++j)
      fold(plan.sendIndices[j], recv[k].data() + static_cast<std::size_t>(j - plan.sendOffsets[k]) * c);
}

void copyOwnersToGhosts(MPI_Comm comm, const HaloPlan& plan, int components, std::vector<double>& values) {
  const std::size_t c = static_cast<std::size_t>(components);
  MFSI_CHECK(values.size() == static_cast<std::size_t>(plan.nLocal) * c,
             "copy to ghosts: " << values.size() << " values for " << plan.nLocal << " entries of " << components);
  const std::size_t nb = plan.neighbours.size();
  std::vector<std::vector<double>> send(nb), recv(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    for (lid_t j = plan.sendOffsets[k]; j < plan.sendOffsets[k + 1]; ++j) {
      const std::size_t i = static_cast<std::size_t>(plan.sendIndices[j]);
      send[k].insert(send[k].end(), values.begin() + i * c, values.begin() + (i + 1) * c);
    }
    recv[k].resize(static_cast<std::size_t>(plan.recvOffsets[k + 1] - plan.recvOffsets[k]) * c);
  }
  swapWithNeighbours(comm, plan, kCopyTag, send, recv);
  for (std::size_t k = 0; k < nb; ++k)
    std::copy(recv[k].begin(), recv[k].end(),
              values.begin() + static_cast<std::size_t>(plan.nOwned + plan.recvOffsets[k]) * c);
}

GatheredRows gatherRowsEverywhere(MPI_Comm comm, const std::vector<gid_t>& ids, const std::vector<double>& values,
                                  int components) {
  const std::size_t c = static_cast<std::size_t>(components);
  MFSI_CHECK(values.size() == ids.size() * c,
             "gather rows: " << values.size() << " values for " << ids.size() << " rows of " << components);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int n = static_cast<int>(ids.size());
  std::vector<int> counts(ranks), offsets(ranks), valueCounts(ranks), valueOffsets(ranks);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
  for (int r = 0; r < ranks; ++r) {
    valueCounts[r] = counts[r] * components;
    valueOffsets[r] = offsets[r] * components;
  }
  const std::size_t total = static_cast<std::size_t>(offsets.back()) + static_cast<std::size_t>(counts.back());
  std::vector<long long> myIds(ids.begin(), ids.end()), allIds(total);
  std::vector<double> allValues(total * c);
  MPI_Allgatherv(myIds.data(), n, MPI_LONG_LONG, allIds.data(), counts.data(), offsets.data(), MPI_LONG_LONG, comm);
  MPI_Allgatherv(values.data(), n * components, MPI_DOUBLE, allValues.data(), valueCounts.data(),
                 valueOffsets.data(), MPI_DOUBLE, comm);
  // Rows in rank order: a stable sort by id keeps the lowest rank's copy first.
  std::vector<std::size_t> order(total);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return allIds[a] < allIds[b]; });
  GatheredRows out;
  for (std::size_t i : order) {
    const gid_t g = static_cast<gid_t>(allIds[i]);
    if (!out.ids.empty() && out.ids.back() == g) continue;
    out.ids.push_back(g);
    out.values.insert(out.values.end(), allValues.begin() + i * c, allValues.begin() + (i + 1) * c);
  }
  return out;
}

}  // namespace mfsi
