// Stopping a run on SIGINT, SIGTERM or SIGHUP. While a StopOnSignals lives (a run writing its
// output folder), such a signal does not end the process: the handler records it and sends
// SIGTERM to every registered child (f3d, Xvfb, gnuplot, ffmpeg), so that a wait for one of them
// returns; the run then stops at its next check_interrupt(), which throws Interrupted. Unwinding
// stops the remaining helpers and removes the staging folder (output_folder.hpp), and the
// command exits with 128 + the signal. A second signal ends the process at once.
#pragma once

#include <sys/types.h>

namespace conform::scenes {

/// Thrown by check_interrupt(). Not a std::exception, so that no handler of a failed step (a
/// warning, a "not drawn") takes a stop for a failure.
struct Interrupted {
  int signal;
  int exit_code() const { return 128 + signal; }
};

class StopOnSignals {
 public:
  /// Installs the handlers (a signal ignored when conform started, e.g. SIGHUP under nohup,
  /// stays ignored) and forgets any signal recorded before.
  StopOnSignals();
  /// Restores the earlier handlers.
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;
};

/// The stop signal that came (0: none).
int interrupt_signal();
/// Throws Interrupted when a stop signal came.
void check_interrupt();
/// "SIGINT", "SIGTERM", … for messages.
const char* signal_name(int signal);

/// The children the handler signals: ChildProcess registers each it starts, and unregisters it
/// before reaping it (a zombie's pid is not reused, so the handler never signals a stranger).
void register_child(pid_t pid);
void unregister_child(pid_t pid);

}  // namespace conform::scenes
