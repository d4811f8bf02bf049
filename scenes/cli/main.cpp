// The `conform` command: headless scenes and tools built on the Conform library.
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "cli/commands.hpp"
#include "conform/version.hpp"

namespace {

// CLI11 reads "nan", "inf" and 1e400 into a double; no command means them (`skin --time nan`
// wrote NaN vertices and exited 0). One check, added to every FLOAT option of every command.
void refuse_non_finite_numbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(text.c_str(), &end);
        if (end == text.c_str()) return {};  // not a number: CLI11's own conversion says so
        return std::isfinite(x) ? std::string() : "must be a finite number, not " + text;
      },
      "FINITE");
  for (CLI::Option* option : app.get_options())
    if (option->get_type_name() == "FLOAT") option->check(finite);
  for (CLI::App* command : app.get_subcommands({})) refuse_non_finite_numbers(*command);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"conform — CGA skinning, cutting and IK for Bullet soft bodies"};
  app.set_version_flag("--version", std::string("conform ") + conform::version());
  conform::cli::Context context;
  conform::cli::register_info(app, context);
  conform::cli::register_ik(app, context);
  conform::cli::register_skin(app, context);
  conform::cli::register_mesh_ops(app, context);
  conform::cli::register_run(app, context);
  conform::cli::register_scenes(app, context);
  conform::cli::register_sweep(app, context);
  refuse_non_finite_numbers(app);
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (app.get_subcommands().empty()) {
    // The main job: the default scene into results/NAME (see `conform --help` for the rest).
    std::cout << "conform " << conform::version() << ": no command given, running the default "
              << "scene '" << conform::cli::default_scene()
              << "' (conform --help lists commands)\n";
    return conform::cli::run_scene(conform::cli::default_scene(), "", 0, {});
  }
  return context.exit_code;
}
