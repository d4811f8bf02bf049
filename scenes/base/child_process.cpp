#include "base/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "base/interrupt.hpp"

extern char** environ;

namespace conform::scenes {

namespace {

// In the child, between fork and exec: only async-signal-safe calls (everything the exec needs
// was made before the fork, which may come from any of conform's threads).
[[noreturn]] void exec_child(pid_t parent, char* const argv[], char* const envp[], const char* log,
                             const char* dir) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);  // the parent died before prctl took effect
  if (*dir && ::chdir(dir) != 0) ::_exit(127);
  const int null = ::open("/dev/null", O_RDWR);
  const int out = *log ? ::open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644) : null;
  if (null >= 0) ::dup2(null, 0);
  if (out >= 0) ::dup2(out, 1), ::dup2(out, 2);
  ::execvpe(argv[0], argv, envp);
  ::_exit(127);
}

int exit_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& args, const ChildOptions& options) {
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e) {
    const std::string entry = *e;
    bool replaced = false;
    for (const auto& mine : options.env) {
      const std::size_t name = mine.find('=') + 1;  // the name and its '='
      replaced |= name > 1 && entry.compare(0, name, mine, 0, name) == 0;
    }
    if (!replaced) env.push_back(entry);
  }
  env.insert(env.end(), options.env.begin(), options.env.end());
  std::vector<std::string> owned_args = args;
  std::vector<char*> argv, envp;
  for (auto& a : owned_args) argv.push_back(a.data());
  for (auto& e : env) envp.push_back(e.data());
  argv.push_back(nullptr);
  envp.push_back(nullptr);
  // The kept descriptor must survive exec.
  if (options.keep_fd >= 0) ::fcntl(options.keep_fd, F_SETFD, 0);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0)
    exec_child(parent, argv.data(), envp.data(), options.log.c_str(), options.dir.c_str());
  if (pid_ < 0) error_ = "cannot start " + args.front() + ": " + std::strerror(errno);
  if (pid_ > 0) register_child(pid_);
}

int ChildProcess::wait() {
  if (pid_ <= 0) return status_;
  // Unregistered once it has exited but before it is reaped: until then its pid is not reused.
  siginfo_t info;
  while (::waitid(P_PID, id_t(pid_), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
  }
  unregister_child(pid_);
  int status = 0;
  pid_t r;
  while ((r = ::waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
  }
  status_ = r == pid_ ? exit_status(status) : -1;
  pid_ = -1;
  return status_;
}

void ChildProcess::stop() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  wait();
}

ChildProcess::~ChildProcess() {
  stop();
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(other.pid_), status_(other.status_), error_(std::move(other.error_)) {
  other.pid_ = -1;
}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    stop();
    pid_ = other.pid_;
    status_ = other.status_;
    error_ = std::move(other.error_);
    other.pid_ = -1;
  }
  return *this;
}

}  // namespace conform::scenes
