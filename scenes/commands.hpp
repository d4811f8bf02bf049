// Subcommands of the `conform` command; each lives in its own cmd_*.cpp and registers itself
// with the CLI11 app. A subcommand returns the process exit code through `exit_code`.
#pragma once

#include <CLI/CLI.hpp>

namespace conform::cli {

struct Context {
  int exit_code = 0;
};

void register_info(CLI::App& app, Context& context);

}  // namespace conform::cli
