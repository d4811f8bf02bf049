// Subcommands of the `conform` command; each lives in its own cmd_*.cpp and registers itself
// with the CLI11 app. A subcommand returns the process exit code through `context.exit_code`
// (errors go to stderr with a non-zero code, never an uncaught exception).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "conform/io/isolation_limits.hpp"

namespace conform::cli {

struct Context {
  int exit_code = 0;
};

void register_info(CLI::App& app, Context& context);      // cmd_info.cpp
void register_ik(CLI::App& app, Context& context);        // cmd_ik.cpp
void register_skin(CLI::App& app, Context& context);      // cmd_skin.cpp
void register_mesh_ops(CLI::App& app, Context& context);  // cmd_mesh_ops.cpp
void register_run(CLI::App& app, Context& context);       // cmd_run.cpp
void register_scenes(CLI::App& app, Context& context);    // cmd_run.cpp
void register_sweep(CLI::App& app, Context& context);     // cmd_sweep.cpp

/// --strict-weights: the one name of io::ImportOptions::strict_weights on every command that
/// loads a model (scene files: model.strict_weights).
inline void add_strict_weights(CLI::App* cmd, bool& strict) {
  cmd->add_flag("--strict-weights", strict,
                "refuse a model whose bone weights do not sum to 1 (default: normalize them "
                "with one warning)");
}

/// --import-seconds, --import-seconds-per-mib, --import-memory: the caps of the isolated import
/// (io::IsolationLimits) on every command that loads a model file.
inline void add_import_limits(CLI::App* cmd, io::IsolationLimits& limits) {
  cmd->add_option("--import-seconds", limits.seconds,
                  "give up reading the model file after this many seconds plus "
                  "--import-seconds-per-mib for every MiB of it (default 2)")
      ->check(CLI::Range(0.001, 86400.0));
  cmd->add_option("--import-seconds-per-mib", limits.seconds_per_mib,
                  "seconds added to the import's time cap per MiB of the file (default 10)")
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_option_function<double>(
         "--import-memory",
         [&limits](double mib) { limits.memory_bytes = static_cast<std::size_t>(mib * 1048576.0); },
         "memory cap of the model file's reader, MiB (default 4096)")
      ->check(CLI::Range(16.0, 1048576.0));
}

/// The scene `conform` runs when given no arguments.
const char* default_scene();
/// Runs a scene (built-in name or file) into `out_dir` (empty: results/NAME); the exit code.
int run_scene(const std::string& scene, const std::string& out_dir, int steps,
              const std::vector<std::string>& sets);

}  // namespace conform::cli
