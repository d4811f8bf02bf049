// A helper program started by conform (Xvfb, f3d, gnuplot, ffmpeg) as its child, from an
// argument vector (no shell): killed by the kernel if conform dies first (PR_SET_PDEATHSIG), so
// no helper outlives a killed run, stopped by a stop signal (interrupt.hpp), and reaped by
// wait() or stop().
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace conform::scenes {

struct ChildOptions {
  std::vector<std::string> env;  // "NAME=value" entries added to (or replacing in) conform's own
  std::string log;               // stdout and stderr go here; "" for /dev/null
  int keep_fd = -1;              // a descriptor the child inherits (e.g. Xvfb's -displayfd)
  std::string dir;               // its working directory; "" for conform's
};

class ChildProcess {
 public:
  ChildProcess() = default;
  /// Starts args[0] (searched on PATH) with args. running() is false when it could not be
  /// forked; a program that cannot be run exits 127.
  ChildProcess(const std::vector<std::string>& args, const ChildOptions& options);
  /// Stops the child (stop()) if it still runs.
  ~ChildProcess();

  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  const std::string& error() const { return error_; }

  /// Waits for the child to exit and returns its exit status (128 + the signal when killed,
  /// -1 when it never ran).
  int wait();
  /// SIGTERM, then waits.
  void stop();

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

 private:
  pid_t pid_ = -1;
  int status_ = -1;
  std::string error_;
};

}  // namespace conform::scenes
