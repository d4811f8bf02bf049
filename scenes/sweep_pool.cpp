#include "sweep_pool.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>

#include "progress.hpp"
#include "sweep_point_run.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

// The sweep's progress: a bar of finished points on a terminal (a failure gets a line of its
// own above it); otherwise a plain line per finished point on stdout.
class SweepProgress {
 public:
  SweepProgress(int total, int skipped)
      : tty_(::isatty(STDERR_FILENO) == 1), bar_("sweep", "point", total, 0), finished_(skipped) {
    if (skipped > 0)
      std::cout << "sweep: " << skipped << " of " << total << " points already finished, skipped\n"
                << std::flush;
    if (tty_) bar_.update(finished_);
  }
  void report(const SweepPoint& p, const PointStatus& s) {
    ++finished_;
    failed_ += s.state == PointStatus::State::Failed;
    char wall[32];
    std::snprintf(wall, sizeof wall, "%.2f s", s.wall_s);
    const std::string line =
        "sweep: point " + std::to_string(p.index) + " (" + p.label() + ") " +
        (s.state == PointStatus::State::Done
             ? std::string("done in ") + wall
             : "FAILED (exit " + std::to_string(s.exit_code) + "): " + s.error);
    if (!tty_) {
      std::cout << line << "\n" << std::flush;
      return;
    }
    if (s.state == PointStatus::State::Failed) bar_.line(line);
    bar_.update(finished_, failed_ ? std::to_string(failed_) + " failed" : "");
  }

 private:
  bool tty_;
  Progress bar_;
  int finished_, failed_ = 0;
};

}  // namespace

PoolResult run_pool(const SweepSpec& spec, const fs::path& dir, int jobs, int only) {
  PoolResult result;
  std::vector<int> todo;
  for (const auto& p : spec.points) {
    if (only >= 0 && p.index != only) continue;
    if (summary_complete(point_dir(dir, p.index)))
      ++result.skipped;
    else
      todo.push_back(p.index);
  }
  SweepProgress progress(result.skipped + static_cast<int>(todo.size()), result.skipped);
  std::map<pid_t, PointProcess> running;
  std::size_t next = 0;
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && static_cast<int>(running.size()) < std::max(1, jobs)) {
      const PointProcess p = start_point(spec, dir, todo[next++]);
      running[p.pid] = p;
    }
    int wstatus = 0;
    const pid_t pid = ::waitpid(-1, &wstatus, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("waitpid failed: " + std::string(std::strerror(errno)));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours (e.g. a gnuplot of a caller)
    const PointStatus s = finish_point(dir, it->second, wstatus);
    progress.report(spec.points[std::size_t(it->second.index)], s);
    (s.state == PointStatus::State::Done ? result.done : result.failed) += 1;
    running.erase(it);
  }
  return result;
}

}  // namespace conform::scenes
