#include "commands.hpp"

namespace conform::cli {

// Placeholder registration: the subcommand is added by its issue's work.
void register_ik(CLI::App&, Context&) {}

}  // namespace conform::cli
