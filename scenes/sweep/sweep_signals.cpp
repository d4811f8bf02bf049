#include "sweep/sweep_signals.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace conform::scenes {

namespace {

constexpr int kSignals[4] = {SIGTERM, SIGINT, SIGHUP, SIGCHLD};
int pipe_fds[2] = {-1, -1};
pid_t owner = -1;

void on_signal(int sig) {
  // A child between fork and exec still runs this handler: only the sweep itself reports.
  if (::getpid() != owner) return;
  const int saved = errno;
  const unsigned char byte = static_cast<unsigned char>(sig);
  [[maybe_unused]] const ssize_t n = ::write(pipe_fds[1], &byte, 1);  // full: a wake-up waits
  errno = saved;
}

}  // namespace

std::string sigabbrev(int signal) {
  const char* name = sigabbrev_np(signal);
  return name ? std::string("SIG") + name : "signal " + std::to_string(signal);
}

SweepInterrupted::SweepInterrupted(int signal)
    : std::runtime_error("stopped by " + sigabbrev(signal)), signal_(signal) {}

SweepSignals::SweepSignals() {
  if (pipe_fds[0] >= 0) throw std::logic_error("SweepSignals: one instance at a time");
  if (::pipe2(pipe_fds, O_CLOEXEC | O_NONBLOCK) != 0)
    throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  owner = ::getpid();
  struct sigaction action = {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  for (int i = 0; i < 4; ++i) ::sigaction(kSignals[i], &action, &old_[i]);
}

SweepSignals::~SweepSignals() {
  for (int i = 0; i < 4; ++i) ::sigaction(kSignals[i], &old_[i], nullptr);
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
  pipe_fds[0] = pipe_fds[1] = -1;
}

int SweepSignals::wait(int timeout_ms) {
  pollfd p = {pipe_fds[0], POLLIN, 0};
  while (::poll(&p, 1, timeout_ms) < 0 && errno == EINTR) {
  }
  int stop = 0;
  unsigned char bytes[64];
  ssize_t n;
  while ((n = ::read(pipe_fds[0], bytes, sizeof bytes)) > 0)
    for (ssize_t i = 0; i < n; ++i)
      if (stop == 0 && bytes[i] != SIGCHLD) stop = bytes[i];
  return stop;
}

}  // namespace conform::scenes
