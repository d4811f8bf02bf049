// The signals of a local sweep: SIGTERM, SIGINT and SIGHUP stop it (the pool stops its points,
// waits for them and the sweep exits 128 + the signal), and SIGCHLD says that a point ended.
// Each handler writes the signal's number to a pipe that the pool waits on, so a signal that
// comes between two checks is not lost, whichever thread the kernel delivers it to.
#pragma once

#include <signal.h>

#include <stdexcept>
#include <string>

namespace conform::scenes {

/// "SIGTERM" for SIGTERM.
std::string sigabbrev(int signal);

/// Thrown by the pool when the sweep was told to stop; its points have ended.
class SweepInterrupted : public std::runtime_error {
 public:
  explicit SweepInterrupted(int signal);
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// Installs the handlers (one instance at a time) and restores the previous ones when it goes.
class SweepSignals {
 public:
  SweepSignals();
  ~SweepSignals();
  SweepSignals(const SweepSignals&) = delete;
  SweepSignals& operator=(const SweepSignals&) = delete;

  /// Waits until a signal has come (at most `timeout_ms`; -1: no limit); returns the first
  /// stopping signal among those that came since the last call, or 0 (only SIGCHLD, or none).
  int wait(int timeout_ms = -1);

 private:
  struct sigaction old_[4] = {};
};

}  // namespace conform::scenes
