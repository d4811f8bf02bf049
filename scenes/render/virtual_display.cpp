#include "render/virtual_display.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace conform::scenes {

namespace {

constexpr int kReadyTimeoutMs = 10000;

}  // namespace

VirtualDisplay::VirtualDisplay(int width, int height) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    error_ = std::string("cannot make a pipe for Xvfb: ") + std::strerror(errno);
    return;
  }
  // Xvfb writes the display number into the child's end once it listens.
  ChildOptions options;
  options.keep_fd = fds[1];
  server_ = ChildProcess(
      {"Xvfb", "-displayfd", std::to_string(fds[1]), "-screen", "0",
       std::to_string(width) + "x" + std::to_string(height) + "x24", "-nolisten", "tcp"},
      options);
  ::close(fds[1]);
  if (!server_.running()) {
    error_ = server_.error();
    ::close(fds[0]);
    return;
  }
  ready_fd_ = fds[0];
}

const std::string& VirtualDisplay::display() {
  std::lock_guard lock(mutex_);
  if (ready_fd_ < 0) return display_;
  std::string number;
  pollfd p{ready_fd_, POLLIN, 0};
  char buf[32];
  // The number ends with a newline; EOF before it means Xvfb exited (or could not be run).
  while (number.find('\n') == std::string::npos) {
    const int r = ::poll(&p, 1, kReadyTimeoutMs);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;  // timed out
    const ssize_t n = ::read(ready_fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    number.append(buf, std::size_t(n));
  }
  ::close(ready_fd_);
  ready_fd_ = -1;
  if (number.empty() || number.find('\n') == std::string::npos)
    error_ = "Xvfb did not start within " + std::to_string(kReadyTimeoutMs / 1000) +
             " s (is it installed? scripts/deps.sh installs xvfb)";
  else
    display_ = ":" + number.substr(0, number.find('\n'));
  return display_;
}

VirtualDisplay::~VirtualDisplay() {
  if (ready_fd_ >= 0) ::close(ready_fd_);
}

}  // namespace conform::scenes
