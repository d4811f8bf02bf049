// The `conform` command: headless scenes and tools built on the Conform library.
#include <iostream>

#include "commands.hpp"
#include "conform/version.hpp"

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
