// `conform run SCENE [--out DIR] [--steps N] [--set KEY=VALUE …]` and `conform scenes`.
// SCENE is a built-in scene name or a JSON scene file. The scene is parsed completely before
// anything is written, so a bad key or value leaves no folder behind; the results are written
// atomically (output_folder.hpp): a failed run leaves the earlier results in --out untouched.
// SIGINT, SIGTERM and SIGHUP stop a run (interrupt.hpp): its helpers and staging folder go, the
// earlier results stay, and it exits 128 + the signal. A run whose plots, pictures or video
// could not all be made is put in place with its failures in summary.json, and exits 1.
#include <omp.h>

#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

#include "base/interrupt.hpp"
#include "base/output_folder.hpp"
#include "cli/commands.hpp"
#include "kinds/scene.hpp"

namespace conform::cli {
namespace {

struct RunArgs {
  std::string scene, out;
  int steps = 0;
  std::vector<std::string> sets;
  bool no_render = false;
  bool vtk = false;
};

void print_metrics(const scenes::Json& j, const std::string& prefix) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it->is_object()) {
      print_metrics(*it, prefix + it.key() + ".");
    } else if (it->is_number() || it->is_boolean()) {
      std::cout << "  " << prefix << it.key() << " = " << it->dump() << "\n";
    }
  }
}

// Every "file" the scene reads (e.g. model.file), and the scene file itself: the results must
// not replace the folder of any of them.
void collect_inputs(const scenes::Json& j, std::vector<std::filesystem::path>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (j.is_object() && it.key() == "file" && it->is_string())
      out.emplace_back(it->get<std::string>());
    if (it->is_structured()) collect_inputs(*it, out);
  }
}

}  // namespace

const char* default_scene() {
  // tear-opening is the main comparison; until its scene kind exists, the best real scene.
  return scenes::find_builtin("tear-opening") ? "tear-opening" : "arm-track";
}

int run_scene(const std::string& scene, const std::string& out_dir, int steps,
              const std::vector<std::string>& sets) {
  std::unique_ptr<scenes::Scene> prepared;
  try {
    prepared = scenes::load_scene(scene, sets, steps);
  } catch (const scenes::SceneError& e) {
    std::cerr << "conform run: " << scene << ": " << e.what() << " (nothing written)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "conform run: " << e.what() << " (nothing written)\n";
    return 2;
  }
  std::vector<std::string> failures;
  const std::filesystem::path dir = out_dir.empty()
                                        ? std::filesystem::path("results") / prepared->common().name
                                        : std::filesystem::path(out_dir);
  try {
    const auto& c = prepared->common();
    std::cout << "conform run " << c.name << " (" << c.kind << "): " << c.steps << " steps of "
              << c.dt << " s, seed " << c.seed << "\n"
              << std::flush;
    if (c.threads > 0) omp_set_num_threads(c.threads);
    std::vector<std::filesystem::path> inputs;
    if (!scenes::find_builtin(scene)) inputs.emplace_back(scene);
    collect_inputs(prepared->resolved(), inputs);
    const scenes::StopOnSignals stop;
    scenes::OutputFolder folder(dir, inputs);
    scenes::Json metrics;
    {
      scenes::RunOutput out(folder.staging(), c);
      metrics = prepared->run(out);
      failures = out.failures();
    }
    scenes::check_interrupt();  // a signal after the last check still keeps the earlier results
    folder.commit();
    const scenes::Json summary =
        scenes::Json::parse(std::ifstream(dir / "summary.json"), nullptr, false);
    std::cout << "metrics:\n";
    print_metrics(metrics, "");
    if (summary.is_object()) {
      const auto& t = summary["timings"];
      std::cout << "timing: " << t.value("wall_per_simulated_second_s", 0.0)
                << " s wall per simulated second, " << t.value("wall_per_step_ms", 0.0)
                << " ms per step (" << t.value("real_time_factor", 0.0) << "x real time)\n";
      for (auto it = summary["plots"].begin(); it != summary["plots"].end(); ++it)
        if (it->get<std::string>().rfind("not drawn", 0) == 0)
          std::cout << "plot " << it.key() << ": " << it->get<std::string>() << "\n";
    }
    std::cout << "results in " << std::filesystem::absolute(dir).lexically_normal().string()
              << "/ (summary.json, metrics.csv, frames/*.ply, *.png"
              << (summary.is_object() && summary["render"].contains("glb") ? ", run.glb" : "")
              << (summary.is_object() &&
                          summary["render"].value("pictures", scenes::Json::array()).size() > 0
                      ? ", pictures/*.png"
                      : "")
              << (summary.is_object() && summary.contains("vtk") && summary["vtk"].contains("pvd")
                      ? ", vtk/series.pvd"
                      : "")
              << ")\n";
    if (!failures.empty()) {
      std::cerr << "conform run: " << prepared->common().name << ": the run is incomplete ("
                << failures.size() << " failure" << (failures.size() > 1 ? "s" : "")
                << ", listed in summary.json):\n";
      for (const auto& f : failures) std::cerr << "  " << f << "\n";
      return 1;
    }
    return 0;
  } catch (const scenes::Interrupted& stop) {
    std::cerr << "conform run: " << prepared->common().name << ": stopped by "
              << scenes::signal_name(stop.signal)
              << "; its staging folder removed, the earlier results in " << dir.string()
              << " untouched\n";
    return stop.exit_code();
  } catch (const scenes::OutputRefused& e) {
    std::cerr << "conform run: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "conform run: " << prepared->common().name << ": " << e.what() << "\n";
    return 1;
  }
}

void register_run(CLI::App& app, Context& context) {
  auto* cmd = app.add_subcommand("run", "Run a scene headless and write its results to a folder");
  auto args = std::make_shared<RunArgs>();
  cmd->add_option("SCENE", args->scene, "built-in scene name (see `conform scenes`) or JSON file")
      ->required();
  cmd->add_option("--out", args->out, "output folder (default: results/SCENE)");
  cmd->add_option("--steps", args->steps, "number of steps (default: the scene's duration / dt)")
      ->check(CLI::Range(1, scenes::kMaxSteps));
  cmd->add_option("--set", args->sets, "override a scene key, e.g. --set physics.dt=0.005")
      ->allow_extra_args(false);
  cmd->add_flag("--no-render", args->no_render,
                "no pictures, video or run.glb (the scene's \"render\": false)");
  cmd->add_flag("--vtk", args->vtk,
                "also write the ParaView series vtk/series.pvd (the scene's outputs.vtk: true)");
  cmd->callback([&context, args]() {
    // Last, so that it wins over any --set render.KEY=VALUE.
    if (args->no_render) args->sets.push_back("render=false");
    if (args->vtk) args->sets.push_back("outputs.vtk=true");
    context.exit_code = run_scene(args->scene, args->out, args->steps, args->sets);
  });
}

void register_scenes(CLI::App& app, Context& context) {
  auto* cmd = app.add_subcommand("scenes", "List the built-in scenes (or print one's JSON)");
  auto show = std::make_shared<std::string>();
  cmd->add_option("--show", *show, "print the scene file of a built-in scene");
  cmd->callback([&context, show]() {
    if (!show->empty()) {
      const auto* b = scenes::find_builtin(*show);
      if (!b) {
        std::cerr << "conform scenes: no built-in scene '" << *show << "'\n";
        context.exit_code = 2;
        return;
      }
      std::cout << b->json << "\n";
      return;
    }
    for (const auto& s : scenes::scene_kinds())
      std::cout << std::left << std::setw(14) << s.name << " " << s.summary << "\n";
  });
}

}  // namespace conform::cli
