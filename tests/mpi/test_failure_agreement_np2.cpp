// How two ranks agree on a run's outcome (core/parallel/FailureAgreement): the same failure on
// both, a failure of one rank alone that the other learns, and a failed rank whose partner is
// elsewhere (waiting in a collective it will never join): it times out instead of hanging.
#include "core/parallel/FailureAgreement.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

using namespace mfsi;

namespace {
struct Comm {
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0;
  Comm() {
    MPI_Comm_dup(MPI_COMM_WORLD, &comm);
    MPI_Comm_rank(comm, &rank);
  }
  ~Comm() { MPI_Comm_free(&comm); }
};

/// The agreement completed and every rank holds rank `first`'s outcome `expected`.
void expectAgreed(const FailureAgreement& a, int first, const RankOutcome& expected) {
  EXPECT_TRUE(a.complete);
  EXPECT_EQ(a.firstFailed, first);
  EXPECT_EQ(a.outcome.code, expected.code);
  EXPECT_EQ(a.outcome.status, expected.status);
  EXPECT_EQ(a.outcome.error, expected.error);
  EXPECT_EQ(a.outcome.message, expected.message);
}
}  // namespace

TEST(FailureAgreement, SuccessEverywhereIsNoFailure) {
  Comm c;
  expectAgreed(agreeOnOutcome(c.comm, {}, 1.0), -1, {});
}

TEST(FailureAgreement, TheSameFailureOnEveryRankIsRankZeros) {
  Comm c;
  const RankOutcome mine{3, "diverged", "at t = 0.5", "diverged at t = 0.5 (rank " + std::to_string(c.rank) + ")"};
  expectAgreed(agreeOnOutcome(c.comm, mine, 10.0), 0, {3, "diverged", "at t = 0.5", "diverged at t = 0.5 (rank 0)"});
}

TEST(FailureAgreement, OneRanksFailureReachesTheOther) {
  Comm c;
  const RankOutcome failed{1, "error", "out of memory", "internal error on rank 1: out of memory"};
  expectAgreed(agreeOnOutcome(c.comm, c.rank == 1 ? failed : RankOutcome{}, 10.0), 1, failed);
}

TEST(FailureAgreement, AFailedRankDoesNotWaitForOneThatIsElsewhere) {
  Comm c;
  if (c.rank == 1) {
    const auto t0 = std::chrono::steady_clock::now();
    FailureAgreement a = agreeOnOutcome(c.comm, {2, "error", "alone", "rank 1 alone"}, 0.3);
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(a.complete);
    EXPECT_GE(waited, 0.3);
    EXPECT_LT(waited, 1.5);  // rank 0 joins only after 2 s
    MPI_Wait(&a.pending, MPI_STATUS_IGNORE);  // (a run would abort here; the test closes the reduction)
  } else {
    std::this_thread::sleep_for(std::chrono::seconds(2));  // "in a collective rank 1 left"
    // Close the reduction rank 1 opened (a run's rank 1 aborts the job instead).
    // (Non-blocking: a blocking collective never matches a non-blocking one.)
    int ranks = 2, first = 0;
    MPI_Request r;
    MPI_Iallreduce(&ranks, &first, 1, MPI_INT, MPI_MIN, c.comm, &r);
    MPI_Wait(&r, MPI_STATUS_IGNORE);
    EXPECT_EQ(first, 1);
  }
}
