#include "commands.hpp"

namespace conform::cli {

// Placeholder registration: the subcommand is added by its issue's work.
void register_mesh_ops(CLI::App&, Context&) {}

}  // namespace conform::cli
