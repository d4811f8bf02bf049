#include "virtual_display.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace conform::scenes {

namespace {

constexpr int kReadyTimeoutMs = 10000;

// In the child, between fork and exec: only async-signal-safe calls (the arguments were made
// before the fork).
[[noreturn]] void exec_xvfb(pid_t parent, char* const argv[]) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);  // the parent died before prctl took effect
  const int null = ::open("/dev/null", O_RDWR);
  if (null >= 0) ::dup2(null, 0), ::dup2(null, 1), ::dup2(null, 2);
  ::execvp(argv[0], argv);
  ::_exit(127);
}

}  // namespace

VirtualDisplay::VirtualDisplay(int width, int height) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    error_ = std::string("cannot make a pipe for Xvfb: ") + std::strerror(errno);
    return;
  }
  // The child's end must survive exec: Xvfb writes the display number into it.
  ::fcntl(fds[1], F_SETFD, 0);
  std::vector<std::string> args{
      "Xvfb",      "-displayfd", std::to_string(fds[1]),
      "-screen",   "0",          std::to_string(width) + "x" + std::to_string(height) + "x24",
      "-nolisten", "tcp"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) exec_xvfb(parent, argv.data());
  ::close(fds[1]);
  if (pid_ < 0) {
    error_ = std::string("cannot start Xvfb: ") + std::strerror(errno);
    ::close(fds[0]);
    return;
  }
  ready_fd_ = fds[0];
}

const std::string& VirtualDisplay::display() {
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
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
}

}  // namespace conform::scenes
