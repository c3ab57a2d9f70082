#pragma once
/// \file
/// \brief SIGINT and SIGTERM as a request to stop a run cleanly: the handler only records the
/// signal; the time loop asks between steps, writes a checkpoint and the summary ("interrupted")
/// and ends with a non-zero exit. A second signal ends the process at once (the default action).
namespace mfsi {

/// Install the handlers of SIGINT and SIGTERM (idempotent).
void installInterruptHandlers();
/// The signal received since the handlers were installed, or 0.
int interruptSignal();
/// "SIGINT", "SIGTERM" or "signal N".
const char* signalName(int signal);

}  // namespace mfsi
