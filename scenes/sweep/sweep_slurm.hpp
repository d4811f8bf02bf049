// A sweep as a Slurm job array: DIR/sweep.sbatch has one array task per point, and task N runs
// `conform sweep --task N DIR`, which reads DIR/sweep.json and writes only DIR/runs/N. The
// tasks share no state, so any scheduler (or GNU parallel, or ssh) can run them the same way.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep/sweep_spec.hpp"

namespace conform::scenes {

struct SlurmOptions {
  std::string partition;  // empty: the cluster's default
  std::string time;       // per task, Slurm's format (e.g. 00:10:00); empty: the default
  int array_limit = 0;    // most tasks running at once (the %K of --array); 0: no limit
  std::string job_name = "conform-sweep";
  std::vector<std::string> lines;  // more directives (--sbatch-line), each written `#SBATCH LINE`
};

/// Throws SceneError naming a bad option (a value with spaces, a time Slurm would not read, a
/// directive that is not one line or would change the array).
void check_slurm_options(const SlurmOptions& options);

/// `s` quoted for sh (single quotes), so that it reads back as one word whatever it holds.
std::string shell_quote(const std::string& s);

/// The command that runs the points `indices` of the job array in DIR/sweep.sbatch again
/// (`sbatch --array=LIST FILE`, with the file's own %LIMIT), or "" when DIR has no sweep.sbatch.
std::string resubmit_command(const std::filesystem::path& dir, const std::vector<int>& indices);

/// Writes DIR/sweep.sbatch (and creates DIR/slurm for the tasks' logs); returns its path.
/// `conform` is the absolute path of the binary the tasks run. Throws on a bad option.
std::filesystem::path write_sbatch(const SweepSpec& spec, const std::filesystem::path& dir,
                                   const std::filesystem::path& conform,
                                   const SlurmOptions& options);

/// Runs `sbatch --parsable FILE` (no shell; its output in DIR/slurm/submit.log) and returns the
/// job id. Throws std::runtime_error with sbatch's own message when it fails or is not installed.
std::string submit_sbatch(const std::filesystem::path& sbatch_file);

}  // namespace conform::scenes
