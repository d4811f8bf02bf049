#include "base/interrupt.hpp"

#include <signal.h>

#include <array>
#include <atomic>
#include <cerrno>

namespace conform::scenes {

namespace {

constexpr std::array<int, 3> kStopSignals = {SIGINT, SIGTERM, SIGHUP};

// Read by the handler: lock-free atomics only (async-signal-safe).
std::atomic<int> g_signal{0};
std::array<std::atomic<pid_t>, 64> g_children{};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free);

struct sigaction g_previous[kStopSignals.size()];

void on_stop_signal(int sig) {
  const int saved_errno = errno;
  int none = 0;
  if (!g_signal.compare_exchange_strong(none, sig)) {
    // A second signal: the user insists, the default action ends the process now.
    ::signal(sig, SIG_DFL);
    ::raise(sig);
  }
  for (auto& child : g_children)
    if (const pid_t pid = child.load(); pid > 0) ::kill(pid, SIGTERM);
  errno = saved_errno;
}

}  // namespace

StopOnSignals::StopOnSignals() {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // Restarted calls: the waits for children end when the handler has killed them, and code
  // that does not expect EINTR keeps working.
  action.sa_flags = SA_RESTART;
  for (std::size_t i = 0; i < kStopSignals.size(); ++i) {
    ::sigaction(kStopSignals[i], nullptr, &g_previous[i]);
    if (g_previous[i].sa_handler != SIG_IGN) ::sigaction(kStopSignals[i], &action, nullptr);
  }
}

StopOnSignals::~StopOnSignals() {
  g_signal = 0;  // handled (Interrupted) or too late to stop anything
  for (std::size_t i = 0; i < kStopSignals.size(); ++i)
    ::sigaction(kStopSignals[i], &g_previous[i], nullptr);
}

int interrupt_signal() {
  return g_signal.load();
}

void check_interrupt() {
  if (const int sig = g_signal.load()) throw Interrupted{sig};
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

void register_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t empty = 0;
    if (child.compare_exchange_strong(empty, pid)) break;
  }
  // A stop that came while the child was being started: it is stopped as the others were.
  if (g_signal.load() != 0) ::kill(pid, SIGTERM);
}

void unregister_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t mine = pid;
    if (child.compare_exchange_strong(mine, 0)) return;
  }
}

}  // namespace conform::scenes
