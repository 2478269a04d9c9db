// Signal handling of a run (see run_signals.hpp).
#include "run/run_signals.hpp"

#include <csignal>

namespace frictherm::coupling::detail {

namespace {

volatile std::sig_atomic_t g_signal = 0;
volatile std::sig_atomic_t g_count = 0;
struct sigaction g_previous_int, g_previous_term, g_previous_usr1;

extern "C" void on_interrupt(int signal) {
  if (g_signal == 0) g_signal = signal;
  // The second is absorbed: `timeout` sends SIGTERM to the process and again to its group, and the run
  // is then writing its last rows and checkpoint. A third takes the default action at once
  // (async-signal-safe: sigaction, raise).
  if (++g_count < 3) return;
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(SIGINT, &dfl, nullptr);
  sigaction(SIGTERM, &dfl, nullptr);
  sigaction(SIGUSR1, &dfl, nullptr);
  raise(signal);
}

}  // namespace

InterruptGuard::InterruptGuard(bool enabled) : enabled_(enabled) {
  if (!enabled_) return;
  g_signal = 0;
  g_count = 0;
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sa.sa_flags = SA_RESTART;  // a write under way when the signal comes goes on (no EINTR in HDF5)
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_previous_int);
  sigaction(SIGTERM, &sa, &g_previous_term);
  // SIGUSR1 too: Open MPI's mpirun forwards it to every rank however often it comes, where a second
  // SIGTERM within 5 s makes mpirun exit at once and the ranks die with it (docs/robustness.md, "Signals").
  sigaction(SIGUSR1, &sa, &g_previous_usr1);
}

InterruptGuard::~InterruptGuard() {
  if (!enabled_) return;
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  sigaction(SIGUSR1, &g_previous_usr1, nullptr);
}

int interrupt_signal() { return static_cast<int>(g_signal); }

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGUSR1: return "SIGUSR1";
    default: return "a signal";
  }
}

}  // namespace frictherm::coupling::detail
