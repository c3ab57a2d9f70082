#include "core/Interrupt.hpp"

#include <csignal>

namespace mfsi {

namespace {
volatile std::sig_atomic_t received = 0;

extern "C" void onInterrupt(int signal) {
  received = signal;
  // The next one is not caught: a run that does not reach the end of its step can still be killed.
  std::signal(signal, SIG_DFL);
}
}  // namespace

void installInterruptHandlers() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
}

int interruptSignal() { return received; }

const char* signalName(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "a signal";
  }
}

}  // namespace mfsi
