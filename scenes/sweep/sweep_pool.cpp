#include "sweep/sweep_pool.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>

#include "base/progress.hpp"
#include "sweep/sweep_point_run.hpp"
#include "sweep/sweep_signals.hpp"

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

namespace {

// The points running now. Leaving early (a signal, an error) stops them and waits for them:
// no point outlives the pool.
class RunningPoints {
 public:
  ~RunningPoints() { stop(nullptr); }
  void add(const PointProcess& p) { points_[p.pid] = p; }
  std::size_t size() const { return points_.size(); }

  /// Reaps every point that has ended, calling `ended(process, wait status)` for each.
  template <class Ended>
  void reap(Ended ended) {
    for (auto it = points_.begin(); it != points_.end();) {
      int wstatus = 0;
      const pid_t r = ::waitpid(it->first, &wstatus, WNOHANG);
      if (r == 0 || (r < 0 && errno == EINTR)) {
        ++it;
        continue;
      }
      if (r == it->first) ended(it->second, wstatus);
      it = points_.erase(it);  // or not ours to wait for any more (ECHILD)
    }
  }

  /// SIGTERM to every point, then waits for them all; a stopping signal meanwhile (a second
  /// Ctrl-C) sends SIGKILL. Without `signals` it waits without listening.
  void stop(SweepSignals* signals) {
    for (const auto& [pid, p] : points_) ::kill(pid, SIGTERM);
    const auto forget = [](const PointProcess&, int) {};
    while (!points_.empty()) {
      reap(forget);
      if (points_.empty()) break;
      if (!signals) {
        int wstatus = 0;
        if (::waitpid(points_.begin()->first, &wstatus, 0) >= 0 || errno != EINTR)
          points_.erase(points_.begin());
      } else if (signals->wait() != 0) {
        for (const auto& [pid, p] : points_) ::kill(pid, SIGKILL);
      }
    }
  }

 private:
  std::map<pid_t, PointProcess> points_;
};

}  // namespace

PoolResult run_pool(const SweepSpec& spec, const fs::path& dir, int jobs, int only, int lock_fd) {
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
  SweepSignals signals;  // before the first fork: no SIGCHLD is missed
  RunningPoints running;
  const auto ended = [&](const PointProcess& process, int wstatus) {
    const PointStatus s = finish_point(dir, process, wstatus);
    progress.report(spec.points[std::size_t(process.index)], s);
    (s.state == PointStatus::State::Done ? result.done : result.failed) += 1;
  };
  std::size_t next = 0;
  for (;;) {
    while (next < todo.size() && static_cast<int>(running.size()) < std::max(1, jobs))
      running.add(start_point(spec, dir, todo[next++], lock_fd));
    // A stop that came as the last point ended still stops the sweep.
    const int stop = signals.wait(running.size() > 0 ? -1 : 0);
    if (stop != 0) {
      std::cerr << "conform sweep: " << sigabbrev(stop) << ": stopping " << running.size()
                << " running point" << (running.size() == 1 ? "" : "s") << "\n";
      running.stop(&signals);
      throw SweepInterrupted(stop);
    }
    running.reap(ended);
    if (running.size() == 0 && next == todo.size()) break;
  }
  return result;
}

}  // namespace conform::scenes
