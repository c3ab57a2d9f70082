#include "core/parallel/RowExchange.hpp"

#include "core/Error.hpp"

#include <algorithm>

namespace mfsi {

namespace {
constexpr int kLengthTag = 7421, kColTag = 7422, kValTag = 7423;
static_assert(sizeof(gid_t) == sizeof(long long), "global ids travel as MPI_LONG_LONG");
}  // namespace

int commSize(MPI_Comm comm) {
  int s = 1;
  if (comm != MPI_COMM_NULL) MPI_Comm_size(comm, &s);
  return s;
}

int commRank(MPI_Comm comm) {
  int r = 0;
  if (comm != MPI_COMM_NULL) MPI_Comm_rank(comm, &r);
  return r;
}

GlobalRows exchangeRows(MPI_Comm comm, const HaloPlan& plan, const GlobalRows& owned) {
  const std::size_t nb = plan.neighbours.size();
  const lid_t nGhost = plan.nLocal - plan.nOwned;
  GlobalRows ghosts;
  if (nb == 0) return ghosts;
  // Row lengths first, then columns and values, each in one message per neighbour.
  std::vector<std::vector<int>> sendLen(nb);
  std::vector<std::vector<long long>> sendCol(nb);
  std::vector<std::vector<double>> sendVal(nb);
  for (std::size_t k = 0; k < nb; ++k)
    for (lid_t s = plan.sendOffsets[k]; s < plan.sendOffsets[k + 1]; ++s) {
      const lid_t i = plan.sendIndices[s];
      sendLen[k].push_back(owned.ptr[i + 1] - owned.ptr[i]);
      for (lid_t p = owned.ptr[i]; p < owned.ptr[i + 1]; ++p) {
        sendCol[k].push_back(owned.col[p]);
        sendVal[k].push_back(owned.val[p]);
      }
    }
  std::vector<int> recvLen(nGhost, 0);
  std::vector<MPI_Request> req;
  for (std::size_t k = 0; k < nb; ++k) {
    const int nr = plan.recvOffsets[k + 1] - plan.recvOffsets[k];
    MPI_Request r;
    if (nr > 0) {
      MPI_Irecv(recvLen.data() + plan.recvOffsets[k], nr, MPI_INT, plan.neighbours[k], kLengthTag, comm, &r);
      req.push_back(r);
    }
    if (!sendLen[k].empty()) {
      MPI_Isend(sendLen[k].data(), static_cast<int>(sendLen[k].size()), MPI_INT, plan.neighbours[k], kLengthTag, comm,
                &r);
      req.push_back(r);
    }
  }
  MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE);
  req.clear();
  ghosts.ptr.assign(nGhost + 1, 0);
  for (lid_t g = 0; g < nGhost; ++g) ghosts.ptr[g + 1] = ghosts.ptr[g] + recvLen[g];
  std::vector<long long> col(ghosts.ptr[nGhost]);
  ghosts.val.assign(ghosts.ptr[nGhost], 0.0);
  for (std::size_t k = 0; k < nb; ++k) {
    const lid_t first = ghosts.ptr[plan.recvOffsets[k]], last = ghosts.ptr[plan.recvOffsets[k + 1]];
    MPI_Request r;
    if (last > first) {
      MPI_Irecv(col.data() + first, last - first, MPI_LONG_LONG, plan.neighbours[k], kColTag, comm, &r);
      req.push_back(r);
      MPI_Irecv(ghosts.val.data() + first, last - first, MPI_DOUBLE, plan.neighbours[k], kValTag, comm, &r);
      req.push_back(r);
    }
    if (!sendCol[k].empty()) {
      const int n = static_cast<int>(sendCol[k].size());
      MPI_Isend(sendCol[k].data(), n, MPI_LONG_LONG, plan.neighbours[k], kColTag, comm, &r);
      req.push_back(r);
      MPI_Isend(sendVal[k].data(), n, MPI_DOUBLE, plan.neighbours[k], kValTag, comm, &r);
      req.push_back(r);
    }
  }
  MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE);
  ghosts.col.assign(col.begin(), col.end());
  return ghosts;
}

HaloPlan planFromGhosts(MPI_Comm comm, gid_t ownedStart, lid_t nOwned, const std::vector<gid_t>& ghosts,
                        const std::vector<int>& ghostOwner) {
  const int ranks = commSize(comm), me = commRank(comm);
  HaloPlan p;
  p.nOwned = nOwned;
  p.nLocal = nOwned + static_cast<lid_t>(ghosts.size());
  p.sendOffsets = {0};
  p.recvOffsets = {0};
  if (ranks == 1) {
    MFSI_CHECK(ghosts.empty(), "halo plan: ghosts on a single rank");
    return p;
  }
  // How many ids each rank asks of each other rank, then the ids themselves.
  std::vector<int> askCount(ranks, 0), askedCount(ranks, 0);
  for (std::size_t g = 0; g < ghosts.size(); ++g) {
    MFSI_CHECK(ghostOwner[g] != me && ghostOwner[g] >= 0 && ghostOwner[g] < ranks,
               "halo plan: ghost " << ghosts[g] << " has owner " << ghostOwner[g]);
    MFSI_CHECK(g == 0 || ghostOwner[g - 1] < ghostOwner[g] ||
                   (ghostOwner[g - 1] == ghostOwner[g] && ghosts[g - 1] < ghosts[g]),
               "halo plan: ghosts not sorted by owner and id");
    ++askCount[ghostOwner[g]];
  }
  MPI_Alltoall(askCount.data(), 1, MPI_INT, askedCount.data(), 1, MPI_INT, comm);
  std::vector<int> askOff(ranks + 1, 0), askedOff(ranks + 1, 0);
  for (int r = 0; r < ranks; ++r) {
    askOff[r + 1] = askOff[r] + askCount[r];
    askedOff[r + 1] = askedOff[r] + askedCount[r];
  }
  std::vector<long long> asks(ghosts.begin(), ghosts.end()), asked(askedOff[ranks]);
  MPI_Alltoallv(asks.data(), askCount.data(), askOff.data(), MPI_LONG_LONG, asked.data(), askedCount.data(),
                askedOff.data(), MPI_LONG_LONG, comm);
  for (int r = 0; r < ranks; ++r) {
    if (r == me || (askCount[r] == 0 && askedCount[r] == 0)) continue;
    p.neighbours.push_back(r);
    for (int a = askedOff[r]; a < askedOff[r + 1]; ++a) {
      const gid_t local = asked[a] - ownedStart;
      MFSI_CHECK(local >= 0 && local < nOwned, "halo plan: rank " << r << " asks for " << asked[a]
                                                                  << ", not owned here");
      p.sendIndices.push_back(static_cast<lid_t>(local));
    }
    p.sendOffsets.push_back(static_cast<lid_t>(p.sendIndices.size()));
    p.recvOffsets.push_back(p.recvOffsets.back() + askCount[r]);
  }
  return p;
}

}  // namespace mfsi
