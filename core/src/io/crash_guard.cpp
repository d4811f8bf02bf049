#include "conform/io/crash_guard.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace conform::io {

std::string crash_in_child(const std::function<void()>& work) {
  std::fflush(nullptr);  // buffered output would otherwise be written twice
  const pid_t pid = fork();
  if (pid < 0) return {};
  if (pid == 0) {
    if (const int null = open("/dev/null", O_WRONLY); null >= 0) dup2(null, 2);
    try {
      work();
    } catch (...) {
      _exit(1);
    }
    _exit(0);  // no atexit handlers, no flushing of the parent's copied buffers
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return {};
  if (!WIFSIGNALED(status)) return {};
  const char* name = strsignal(WTERMSIG(status));
  return name ? name : "signal " + std::to_string(WTERMSIG(status));
}

}  // namespace conform::io
