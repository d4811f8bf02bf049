#include "conform/io/isolate.hpp"

#include <fcntl.h>
#include <omp.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <sstream>

#if defined(__SANITIZE_ADDRESS__)
#define CONFORM_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CONFORM_ASAN 1
#endif
#endif

namespace conform::io {
namespace {

// The child's report: one tag byte, the payload's length (8 bytes, native order), the payload.
enum Tag : char { kOk = 'O', kFailed = 'F', kOutOfMemory = 'M' };
constexpr std::size_t kHeader = 1 + sizeof(std::uint64_t);

bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool report(int fd, Tag tag, const std::string& payload) {
  char header[kHeader];
  header[0] = tag;
  const std::uint64_t size = payload.size();
  std::memcpy(header + 1, &size, sizeof size);
  return write_all(fd, header, kHeader) && write_all(fd, payload.data(), payload.size());
}

struct Job {
  int fd;
  const std::function<std::string()>* work;
  bool sent = false;
};

void* run_job(void* arg) {
  Job& job = *static_cast<Job*>(arg);
  try {
    const std::string result = (*job.work)();
    job.sent = report(job.fd, kOk, result);
  } catch (const std::bad_alloc&) {
    job.sent = report(job.fd, kOutOfMemory, "std::bad_alloc");
  } catch (const std::exception& e) {
    job.sent = report(job.fd, kFailed, e.what());
  } catch (...) {
    job.sent = report(job.fd, kFailed, "an exception that is not a std::exception");
  }
  return nullptr;
}

// The child: caps, then the work, then its report. Never returns.
[[noreturn]] void child(int fd, pid_t parent, const std::function<std::string()>& work,
                        const IsolationLimits& limits) {
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(125);  // the parent died before the line above
  if (const int null = open("/dev/null", O_WRONLY); null >= 0) dup2(null, 2);
  // libgomp's thread pool does not survive fork: a parallel region in the child would wait
  // for the parent's workers forever. One thread never touches the pool.
  omp_set_num_threads(1);
#ifndef CONFORM_ASAN
  const rlimit cap{limits.memory_bytes, limits.memory_bytes};
  setrlimit(RLIMIT_AS, &cap);
#else
  (void)limits;
#endif
  Job job{fd, &work};
  // On a thread of its own with a large stack: readers recurse over the file's node hierarchy
  // (assimp's glTF loader overflows 8 MiB on a 20,000-node chain). Reserved, not committed.
  pthread_attr_t attr;
  pthread_t thread;
  bool ran =
      pthread_attr_init(&attr) == 0 && pthread_attr_setstacksize(&attr, limits.stack_bytes) == 0 &&
      pthread_create(&thread, &attr, run_job, &job) == 0 && pthread_join(thread, nullptr) == 0;
  if (!ran) run_job(&job);    // no thread: on this one
  _exit(job.sent ? 0 : 124);  // no atexit handlers, no flushing of the parent's copied buffers
}

// The child's resident memory in bytes (0 when /proc cannot tell); used under ASan only.
[[maybe_unused]] std::size_t resident_bytes(pid_t pid) {
  const std::string path = "/proc/" + std::to_string(pid) + "/statm";
  FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return 0;
  unsigned long long pages = 0, resident = 0;
  const bool read = std::fscanf(f, "%llu %llu", &pages, &resident) == 2;
  std::fclose(f);
  return read ? std::size_t(resident) * std::size_t(sysconf(_SC_PAGESIZE)) : 0;
}

enum class Ending { closed, timed_out, over_memory };

// Reads the child's pipe to its end or until `seconds` have passed. Under ASan, where the
// child has no RLIMIT_AS, its resident memory is polled (every 20 ms) against `memory_cap`.
Ending read_until_closed(int fd, pid_t pid, double seconds, std::size_t memory_cap,
                         std::string& out) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
#ifndef CONFORM_ASAN
  (void)pid, (void)memory_cap;
  const long long poll_ms = 1 << 30;
#else
  const long long poll_ms = 20;
#endif
  char buffer[1 << 16];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return Ending::timed_out;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), poll_ms)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return Ending::closed;  // taken as closed: the report is then incomplete
#ifdef CONFORM_ASAN
    if (resident_bytes(pid) > memory_cap) return Ending::over_memory;
#endif
    if (ready == 0) continue;
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Ending::closed;
    out.append(buffer, static_cast<std::size_t>(n));
  }
}

int wait_for(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 0;
  return status;
}

std::string how_it_died(int status) {
  if (WIFSIGNALED(status)) {
    const char* name = strsignal(WTERMSIG(status));
    return name ? name : "signal " + std::to_string(WTERMSIG(status));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    return "exit status " + std::to_string(WEXITSTATUS(status)) + " without a report";
  return "no complete report";
}

// The outcome from what the child sent and how it ended.
Isolated interpret(const std::string& bytes, int status) {
  Isolated out;
  std::uint64_t size = 0;
  if (bytes.size() >= kHeader) std::memcpy(&size, bytes.data() + 1, sizeof size);
  const bool complete = bytes.size() >= kHeader && bytes.size() - kHeader == size;
  if (!complete || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    out.status = Isolated::Status::crashed;
    out.message = how_it_died(status);
    return out;
  }
  std::string payload = bytes.substr(kHeader);
  switch (bytes[0]) {
    case kOk:
      out.status = Isolated::Status::ok;
      out.result = std::move(payload);
      break;
    case kOutOfMemory:
      out.status = Isolated::Status::out_of_memory;
      out.message = std::move(payload);
      break;
    case kFailed:
      out.status = Isolated::Status::failed;
      out.message = std::move(payload);
      break;
    default:
      out.status = Isolated::Status::crashed;
      out.message = "a garbled report";
  }
  return out;
}

}  // namespace

Isolated run_isolated(const std::function<std::string()>& work, const IsolationLimits& limits) {
  Isolated out;
  if (!(limits.seconds > 0) || !std::isfinite(limits.seconds) || limits.memory_bytes == 0) {
    std::ostringstream why;
    why << "invalid limits (seconds " << limits.seconds << ", memory " << limits.memory_bytes
        << " bytes)";
    out.message = why.str();
    return out;
  }
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    out.message = std::string("pipe: ") + std::strerror(errno);
    return out;
  }
  std::fflush(nullptr);  // buffered output would otherwise be written twice
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    out.message = std::string("fork: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return out;
  }
  if (pid == 0) {
    close(fds[0]);
    child(fds[1], parent, work, limits);
  }
  close(fds[1]);
  std::string bytes;
  const Ending ending = read_until_closed(fds[0], pid, limits.seconds, limits.memory_bytes, bytes);
  close(fds[0]);
  if (ending != Ending::closed) kill(pid, SIGKILL);
  const int status = wait_for(pid);
  if (ending == Ending::timed_out) {
    out.status = Isolated::Status::timed_out;
    std::ostringstream why;
    why << "still running after " << limits.seconds << " s";
    out.message = why.str();
    return out;
  }
  if (ending == Ending::over_memory) {
    out.status = Isolated::Status::out_of_memory;
    out.message = "resident memory over the cap";
    return out;
  }
  return interpret(bytes, status);
}

}  // namespace conform::io
