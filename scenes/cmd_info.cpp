#include <iostream>

#include "commands.hpp"
#include "conform/bullet/convert.hpp"
#include "conform/version.hpp"

namespace conform::cli {

void register_info(CLI::App& app, Context& context) {
  auto* cmd = app.add_subcommand("info", "Print the version, the Bullet precision and the features");
  cmd->callback([&context]() {
    std::cout << "conform " << conform::version() << "\n"
              << "  Bullet precision: " << conform::bullet::bullet_precision() << "\n"
              << "  algebra: G(4,1) multivectors, motors, dilators, versors (conform::core)\n";
    context.exit_code = 0;
  });
}

}  // namespace conform::cli
