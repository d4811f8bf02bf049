// One point of a sweep run as its own `conform run` child process (the same binary,
// /proc/self/exe, killed with the sweep) with --out DIR/runs/NNNNN, which the run writes
// atomically (output_folder.hpp: the folder appears complete or not at all). Beside it the sweep
// keeps its own records of the point: NNNNN.out (the run's stdout), NNNNN.err (its stderr) and
// NNNNN.status.json (exit status, error, wall time). A point is finished when its summary.json
// is complete; finished points are not run again.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>

#include "sweep/sweep_spec.hpp"

namespace conform::scenes {

struct PointStatus {
  enum class State { Missing, Done, Failed };
  State state = State::Missing;
  int exit_code = -1;  // of `conform run` (-1: not known)
  std::string error;   // the run's last line on stderr, or how it died
  double wall_s = 0;   // of the child process, as the sweep measured it
};

/// DIR/runs/NNNNN.EXT: one of the sweep's records of point `index` ("out", "err", "status.json").
std::filesystem::path point_record(const std::filesystem::path& dir, int index,
                                   const std::string& ext);

/// Whether `folder`/summary.json is a complete summary.
bool summary_complete(const std::filesystem::path& folder);

/// The point's state: Done (exit code 0) with a complete summary, Failed with a status record
/// of a failure, Missing otherwise.
PointStatus read_status(const std::filesystem::path& dir, int index);

/// A started child: its pid and when it started.
struct PointProcess {
  pid_t pid = -1;
  int index = -1;
  double started = 0;  // seconds on the monotonic clock
};

/// Starts the point's `conform run` (stdout and stderr to the folder, stdin from /dev/null). It
/// gets SIGTERM when the calling thread ends (call it from the main thread), and inherits
/// `inherit_fd` (-1: none). Throws std::runtime_error when the process cannot be started.
PointProcess start_point(const SweepSpec& spec, const std::filesystem::path& dir, int index,
                         int inherit_fd = -1);

/// Records a child that ended with wait status `wstatus` into status.json; returns the status.
PointStatus finish_point(const std::filesystem::path& dir, const PointProcess& process,
                         int wstatus);

/// Seconds on the monotonic clock.
double monotonic_seconds();

}  // namespace conform::scenes
