// The local process pool of `conform sweep`: at most `jobs` points run at once, each its own
// `conform run` child. Finished points are skipped; a failed point is recorded and the others
// go on. Progress is a bar on a terminal (stderr) and one plain line per point otherwise.
#pragma once

#include <filesystem>

#include "sweep_spec.hpp"

namespace conform::scenes {

struct PoolResult {
  int skipped = 0;  // already finished before this run
  int done = 0;     // finished now
  int failed = 0;
};

/// Runs the points of `spec` (all of them, or only `only` when it is >= 0) into `dir`.
PoolResult run_pool(const SweepSpec& spec, const std::filesystem::path& dir, int jobs,
                    int only = -1);

}  // namespace conform::scenes
