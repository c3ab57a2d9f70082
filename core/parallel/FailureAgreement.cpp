#include "core/parallel/FailureAgreement.hpp"

#include "core/Error.hpp"

#include <chrono>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <thread>
#include <vector>

namespace mfsi {

namespace {

/// Rank `root`'s outcome on every rank (all ranks have joined: a blocking broadcast is safe).
RankOutcome broadcastOutcome(MPI_Comm comm, int root, const RankOutcome& mine) {
  int me = 0;
  MPI_Comm_rank(comm, &me);
  const std::string* fields[3] = {&mine.status, &mine.error, &mine.message};
  int head[4] = {mine.code, 0, 0, 0};
  std::vector<char> text;
  if (me == root)
    for (int k = 0; k < 3; ++k) {
      head[k + 1] = static_cast<int>(fields[k]->size());
      text.insert(text.end(), fields[k]->begin(), fields[k]->end());
    }
  MPI_Bcast(head, 4, MPI_INT, root, comm);
  text.resize(static_cast<std::size_t>(head[1]) + head[2] + head[3]);
  if (!text.empty()) MPI_Bcast(text.data(), static_cast<int>(text.size()), MPI_CHAR, root, comm);
  RankOutcome out;
  out.code = head[0];
  auto at = text.begin();
  std::string* outs[3] = {&out.status, &out.error, &out.message};
  for (int k = 0; k < 3; ++k) {
    outs[k]->assign(at, at + head[k + 1]);
    at += head[k + 1];
  }
  return out;
}

}  // namespace

FailureAgreement agreeOnOutcome(MPI_Comm comm, const RankOutcome& mine, double timeoutSeconds) {
  int me = 0, ranks = 1;
  MPI_Comm_rank(comm, &me);
  MPI_Comm_size(comm, &ranks);
  FailureAgreement a;
  int candidate = mine.code != 0 ? me : ranks, first = ranks;
  MPI_Iallreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, comm, &a.pending);
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int done = 0;
    MPI_Test(&a.pending, &done, MPI_STATUS_IGNORE);
    if (done) break;
    if (mine.code != 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeoutSeconds)
      return a;  // the others wait in a collective this rank left: not complete
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  a.complete = true;
  if (first < ranks) {
    a.firstFailed = first;
    a.outcome = broadcastOutcome(comm, first, mine);
  }
  return a;
}

void runOnOneRank(MPI_Comm comm, int root, const std::function<void()>& work) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::uint64_t head[2] = {0, 0};  // 0 done, 1 an input error, 2 another failure; message length
  std::string message;
  std::exception_ptr failure;
  if (rank == root) {
    try {
      work();
    } catch (const InputError& e) {
      head[0] = 1;
      message = e.what();
      failure = std::current_exception();
    } catch (const std::exception& e) {
      head[0] = 2;
      message = e.what();
      failure = std::current_exception();
    }
    head[1] = message.size();
  }
  MPI_Bcast(head, 2, MPI_UINT64_T, root, comm);
  if (head[0] == 0) return;
  message.resize(head[1]);
  MPI_Bcast(message.data(), static_cast<int>(head[1]), MPI_CHAR, root, comm);
  if (failure) std::rethrow_exception(failure);
  if (head[0] == 1) throw InputError(message);
  throw std::runtime_error(message);
}

}  // namespace mfsi
