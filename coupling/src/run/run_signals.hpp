#pragma once
// SIGINT / SIGTERM / SIGUSR1 during a run: the first one asks the run loop to stop after the current step
// (final checkpoint, flush, status `interrupted`, exit code 128 + signal); a second one is absorbed
// (`timeout` sends two), a third ends the process at once (the file keeps what its last flush held).
namespace frictherm::coupling::detail {

/// Installs the handlers for its lifetime when `enabled` (the library never does so unasked:
/// RunOptions::handle_signals), and restores the previous ones after.
class InterruptGuard {
 public:
  explicit InterruptGuard(bool enabled);
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  bool enabled_;
};

/// The signal received since the guard was installed (SIGINT, SIGTERM, SIGUSR1), or 0.
int interrupt_signal();

/// "SIGINT" / "SIGTERM" / "SIGUSR1" / "a signal".
const char* signal_name(int signal);

}  // namespace frictherm::coupling::detail
