#pragma once
/// \file
/// \brief How the ranks of a run agree on its outcome when some of them failed: one message and
/// one summary, never a hang.
///
/// Most failures of a decomposed run arise on every rank at once (an input error of the scene every
/// rank reads, a divergence decided by a global reduction): every rank arrives here with the same
/// failure and rank 0 reports it. A failure of one rank alone (an exception after the last
/// collective it shared with the others, or before one they are now waiting in) is what this is
/// for: every rank, failed or not, joins a non-blocking reduction on a communicator of its own
/// (so it can never be matched with a solver's collective). When all have joined, the lowest
/// failed rank's code, status and message reach every rank. A failed rank that waits longer than
/// its timeout knows the others are stuck in a collective it will never enter: the caller then
/// reports on that rank and aborts the job.
#include <mpi.h>

#include <functional>
#include <string>

namespace mfsi {

/// \brief One rank's outcome: code 0 is success.
struct RankOutcome {
  int code = 0;
  std::string status;   ///< summary.json's status ("error", "diverged", ...)
  std::string error;    ///< summary.json's error
  std::string message;  ///< the line the run prints
};

struct FailureAgreement {
  bool complete = false;  ///< every rank joined within the timeout
  int firstFailed = -1;   ///< the lowest failed rank (-1: none); valid when complete
  RankOutcome outcome;    ///< that rank's outcome (when complete): the one the run reports
  MPI_Request pending = MPI_REQUEST_NULL;  ///< when not complete: the reduction still open
};

/// \brief Collective over `comm` (a communicator used for nothing else). A rank that succeeded
/// waits as long as it takes; a failed one at most `timeoutSeconds`.
FailureAgreement agreeOnOutcome(MPI_Comm comm, const RankOutcome& mine, double timeoutSeconds);

/// \brief Work that rank `root` alone does (what only it holds: the whole mesh it read, a
/// membrane's cells). When it fails every rank fails: `root` with its own exception, the others
/// with an error of the same kind (an InputError, or else a std::runtime_error) and message.
/// Collective over `comm`; the others wait in a broadcast while `root` works.
void runOnOneRank(MPI_Comm comm, int root, const std::function<void()>& work);

}  // namespace mfsi
