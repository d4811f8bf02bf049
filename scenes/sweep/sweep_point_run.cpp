#include "sweep/sweep_point_run.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>

namespace conform::scenes {

namespace fs = std::filesystem;

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

fs::path point_record(const fs::path& dir, int index, const std::string& ext) {
  fs::path p = point_dir(dir, index);
  return p.replace_filename(p.filename().string() + "." + ext);
}

bool summary_complete(const fs::path& folder) {
  std::ifstream in(folder / "summary.json");
  if (!in) return false;
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("metrics") && j["metrics"].is_object() &&
         j.contains("timings") && j["timings"].is_object();
}

PointStatus read_status(const fs::path& dir, int index) {
  PointStatus s;
  std::ifstream in(point_record(dir, index, "status.json"));
  const Json j = in ? Json::parse(in, nullptr, false) : Json();
  if (j.is_object()) {
    s.exit_code = j.value("exit_code", -1);
    s.error = j.value("error", "");
    s.wall_s = j.value("wall_s", 0.0);
  }
  if (summary_complete(point_dir(dir, index))) {
    // A complete summary is the point's result. A record of another outcome (none, or an
    // attempt that failed while another run of the point finished it) is not this result's.
    s.state = PointStatus::State::Done;
    if (s.exit_code != 0) s = {PointStatus::State::Done, 0, "", 0.0};
  } else if (j.is_object() && s.exit_code != 0) {
    s.state = PointStatus::State::Failed;
  }
  return s;
}

namespace {

// In the child, between fork and exec: only async-signal-safe calls (everything the exec needs
// was made before the fork).
[[noreturn]] void exec_point(pid_t sweep, char* const argv[], int out, int err, int keep_fd) {
  // The same binary as this process, whatever PATH says.
  // The kernel sends SIGTERM when the sweep dies, however it dies (the run then ends as it does
  // on a kill: nothing half-written is kept). It follows the forking thread: the pool forks
  // from the sweep's main thread.
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != sweep) ::_exit(127);  // the sweep died before prctl took effect
  // The sweep's own handlers and mask are not the run's.
  struct sigaction dfl = {};
  dfl.sa_handler = SIG_DFL;
  for (int sig : {SIGTERM, SIGINT, SIGHUP, SIGCHLD}) ::sigaction(sig, &dfl, nullptr);
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  const int null = ::open("/dev/null", O_RDONLY);
  if (null < 0 || ::dup2(null, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(127);
  if (keep_fd >= 0) ::fcntl(keep_fd, F_SETFD, 0);  // the sweep's lock, held while the run lives
  ::execv("/proc/self/exe", argv);
  const char message[] = "conform sweep: cannot run /proc/self/exe\n";
  [[maybe_unused]] const ssize_t n = ::write(2, message, sizeof message - 1);
  ::_exit(127);
}

int open_record(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
  return fd;
}

}  // namespace

PointProcess start_point(const SweepSpec& spec, const fs::path& dir, int index, int inherit_fd) {
  const fs::path folder = point_dir(dir, index);
  std::error_code ec;
  fs::create_directories(folder.parent_path(), ec);
  if (ec)
    throw std::runtime_error("cannot create " + folder.parent_path().string() + ": " +
                             ec.message());
  // A stale failure must not outlive a new attempt.
  fs::remove(point_record(dir, index, "status.json"), ec);
  std::vector<std::string> args = spec.run_arguments(spec.points.at(std::size_t(index)), folder);
  args.insert(args.begin(), "conform");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int out = open_record(point_record(dir, index, "out"));
  int err = -1;
  try {
    err = open_record(point_record(dir, index, "err"));
  } catch (...) {
    ::close(out);
    throw;
  }
  PointProcess p;
  p.index = index;
  p.started = monotonic_seconds();
  const pid_t sweep = ::getpid();
  p.pid = ::fork();
  if (p.pid == 0) exec_point(sweep, argv.data(), out, err, inherit_fd);
  const int fork_error = errno;
  ::close(out);
  ::close(err);
  if (p.pid < 0)
    throw std::runtime_error("cannot start conform run for point " + std::to_string(index) + ": " +
                             std::strerror(fork_error));
  return p;
}

namespace {

std::string last_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

PointStatus finish_point(const fs::path& dir, const PointProcess& process, int wstatus) {
  const fs::path folder = point_dir(dir, process.index);
  PointStatus s;
  s.wall_s = monotonic_seconds() - process.started;
  if (WIFEXITED(wstatus)) {
    s.exit_code = WEXITSTATUS(wstatus);
    if (s.exit_code != 0) s.error = last_line(point_record(dir, process.index, "err"));
  } else if (WIFSIGNALED(wstatus)) {
    s.exit_code = 128 + WTERMSIG(wstatus);
    s.error = std::string("killed by signal ") + std::to_string(WTERMSIG(wstatus)) + " (" +
              strsignal(WTERMSIG(wstatus)) + ")";
  }
  if (s.exit_code == 0 && !summary_complete(folder)) {
    s.exit_code = 1;
    s.error = "conform run exited 0 but wrote no complete summary.json";
  }
  if (s.exit_code != 0 && s.error.empty()) s.error = "exit status " + std::to_string(s.exit_code);
  s.state = s.exit_code == 0 ? PointStatus::State::Done : PointStatus::State::Failed;
  const Json j = {{"index", process.index},
                  {"exit_code", s.exit_code},
                  {"error", s.error},
                  {"wall_s", s.wall_s}};
  const fs::path record = point_record(dir, process.index, "status.json");
  const fs::path tmp = record.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(2) << "\n";
  }
  std::error_code ec;
  fs::rename(tmp, record, ec);
  return s;
}

}  // namespace conform::scenes
