// The local process pool of `conform sweep`: at most `jobs` points run at once, each its own
// `conform run` child. Finished points are skipped; a failed point is recorded and the others
// go on. No point outlives the sweep (sweep_point_run.hpp, sweep_signals.hpp). Progress is a bar on
// a terminal (stderr) and one plain line per point otherwise.
#pragma once

#include <filesystem>

#include "sweep/sweep_spec.hpp"

namespace conform::scenes {

struct PoolResult {
  int skipped = 0;  // already finished before this run
  int done = 0;     // finished now
  int failed = 0;
};

/// Runs the points of `spec` (all of them, or only `only` when it is >= 0) into `dir`; the
/// points inherit `lock_fd` (the sweep's lock, sweep_lock.hpp; -1: none). On SIGTERM, SIGINT or
/// SIGHUP it stops the running points, waits for them and throws SweepInterrupted: a stopped
/// point is left missing (no record), and running the sweep again resumes it.
PoolResult run_pool(const SweepSpec& spec, const std::filesystem::path& dir, int jobs,
                    int only = -1, int lock_fd = -1);

}  // namespace conform::scenes
