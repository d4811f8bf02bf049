// `conform sweep SCENE --grid KEY=V1,V2,... [--zip ...] [--repeat N] --out DIR`: many runs of
// a scene, each its own `conform run` in DIR/runs/NNNNN, then one table (DIR/sweep.csv) and
// gnuplot plots (DIR/plots). Locally through a process pool (--jobs), or as a Slurm job array
// (--slurm writes DIR/sweep.sbatch, --submit submits it) whose tasks are
// `conform sweep --task N DIR`; `conform sweep --gather DIR` collects what has finished.
#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <thread>

#include "cli/commands.hpp"
#include "conform/version.hpp"
#include "kinds/scene.hpp"
#include "sweep/sweep_lock.hpp"
#include "sweep/sweep_plots.hpp"
#include "sweep/sweep_pool.hpp"
#include "sweep/sweep_signals.hpp"
#include "sweep/sweep_slurm.hpp"
#include "sweep/sweep_table.hpp"

namespace conform::cli {
namespace {

namespace fs = std::filesystem;
using scenes::SweepSpec;

struct SweepArgs {
  std::string target;  // SCENE, or DIR with --task / --gather
  std::string out;
  std::vector<std::string> grids, zips, sets, plot;
  int repeat = 1, steps = 0, jobs = 0, task = -1, array_limit = 0;
  bool gather = false, slurm = false, submit = false;
  std::string partition, time;
  std::vector<std::string> sbatch_lines;
};

// A word for sh: as it is when that is safe, quoted otherwise.
std::string word(const std::string& s) {
  const bool plain = !s.empty() && s.find_first_not_of(
                                       "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMN"
                                       "OPQRSTUVWXYZ0123456789_-+=.,/:@%") == std::string::npos;
  return plain ? s : scenes::shell_quote(s);
}

// The sweep's command, to be pasted into a shell from any folder (it resumes the sweep).
std::string command_line(const SweepArgs& a, const std::string& scene) {
  std::string s = "conform sweep " + word(scene);
  for (const auto& g : a.grids) s += " --grid " + word(g);
  for (const auto& z : a.zips) s += " --zip " + word(z);
  for (const auto& x : a.sets) s += " --set " + word(x);
  if (a.repeat > 1) s += " --repeat " + std::to_string(a.repeat);
  if (a.steps > 0) s += " --steps " + std::to_string(a.steps);
  if (!a.plot.empty()) {
    std::string metrics;
    for (std::size_t i = 0; i < a.plot.size(); ++i) metrics += (i ? "," : "") + a.plot[i];
    s += " --plot " + word(metrics);
  }
  return s + " --out " + word(fs::absolute(a.out).lexically_normal().string());
}

// The sweep described by the arguments, every point validated; nothing is written.
SweepSpec plan(const SweepArgs& a) {
  SweepSpec spec;
  spec.version = conform::version();
  // A scene file is named by its absolute path: tasks may run from any folder.
  spec.scene = scenes::find_builtin(a.target) || !fs::exists(a.target)
                   ? a.target
                   : fs::absolute(a.target).lexically_normal().string();
  spec.command = command_line(a, spec.scene);
  spec.steps = a.steps;
  spec.sets = a.sets;
  spec.repeat = a.repeat;
  spec.plot = a.plot;
  for (const auto& g : a.grids) spec.axes.push_back(scenes::parse_axis("--grid", g, false));
  for (const auto& z : a.zips) spec.axes.push_back(scenes::parse_axis("--zip", z, true));
  spec.points = scenes::expand(spec.axes, a.repeat);
  scenes::validate_points(spec);
  return spec;
}

// How to run the failed and missing points again: the array's tasks when the sweep has a job
// array, and the sweep's own command (which skips finished points).
void print_rerun(const SweepSpec& spec, const scenes::SweepTable& table, const fs::path& dir) {
  std::vector<int> todo = table.missing;
  for (const auto& r : table.rows)
    if (r.status.state == scenes::PointStatus::State::Failed) todo.push_back(r.point->index);
  std::sort(todo.begin(), todo.end());
  if (todo.empty()) return;
  const std::string sbatch = scenes::resubmit_command(dir, todo);
  if (!sbatch.empty()) std::cout << "resubmit them: " << sbatch << "\n";
  std::cout << (sbatch.empty() ? "run them again: " : "or run them here: ") << spec.command << "\n";
}

// Table and plots from whatever has finished; the exit code (0: every point finished).
int gather(const SweepSpec& spec, const fs::path& dir) {
  const scenes::SweepTable table = scenes::gather_table(spec, dir);
  scenes::write_table(spec, table, dir);
  const scenes::SweepPlots plots = scenes::draw_sweep_plots(spec, table, dir);
  int failed = 0;
  for (const auto& r : table.rows) failed += r.status.state == scenes::PointStatus::State::Failed;
  std::cout << "sweep: " << table.rows.size() - std::size_t(failed) << " of " << spec.points.size()
            << " points finished, " << failed << " failed, " << table.missing.size()
            << " missing\n";
  for (const auto& r : table.rows)
    if (r.status.state == scenes::PointStatus::State::Failed)
      std::cout << "  failed: point " << r.point->index << " (" << r.point->label() << "): exit "
                << r.status.exit_code << ": " << r.status.error << "\n";
  for (int m : table.missing)
    std::cout << "  missing: point " << m << " (" << spec.points[std::size_t(m)].label() << ")\n";
  for (const auto& p : plots.problems) std::cout << "  plot not drawn: " << p << "\n";
  std::cout << "table: " << (dir / "sweep.csv").string() << "\n";
  for (const auto& p : plots.drawn) std::cout << "plot: " << p << "\n";
  print_rerun(spec, table, dir);
  if (failed == 0 && table.missing.empty()) return 0;
  std::cout << std::flush;
  std::cerr << "conform sweep: " << failed << " of " << spec.points.size() << " points failed, "
            << table.missing.size() << " missing (" << (dir / "sweep.csv").string() << ")\n";
  return 1;
}

// Writes (or checks) DIR/sweep.json: a folder holds one sweep, resumed only with the same runs.
void claim_folder(const SweepSpec& spec, const fs::path& dir) {
  if (fs::exists(dir / "sweep.json")) {
    const SweepSpec old = scenes::read_spec(dir);
    if (!scenes::same_runs(old, spec))
      throw std::runtime_error(dir.string() + " holds another sweep (" + old.command +
                               "): give another --out");
  }
  std::error_code ec;
  fs::create_directories(dir / "runs", ec);
  if (ec) throw std::runtime_error("cannot create " + (dir / "runs").string());
  scenes::write_spec(dir, spec);
}

int sweep_main(const SweepArgs& a) {
  if (a.gather || a.task >= 0) {
    // The sweep is what DIR/sweep.json says: options that would describe another are refused.
    if (a.gather && a.task >= 0)
      throw scenes::SceneError("--task", std::to_string(a.task), "and --gather are exclusive");
    if (!a.grids.empty() || !a.zips.empty() || !a.sets.empty() || !a.plot.empty() ||
        !a.out.empty() || a.steps > 0 || a.repeat > 1 || a.slurm || a.submit ||
        !a.sbatch_lines.empty())
      throw scenes::SceneError(a.gather ? "--gather" : "--task", a.target,
                               "takes only the sweep folder (its sweep.json holds the rest)");
    const fs::path dir = a.target;
    const SweepSpec spec = scenes::read_spec(dir);
    if (a.gather) {
      const scenes::SweepLock lock(dir);  // not while a local sweep writes the table
      return gather(spec, dir);
    }
    if (a.task >= static_cast<int>(spec.points.size()))
      throw scenes::SceneError(
          "--task", std::to_string(a.task),
          "is not a point of this sweep (0.." + std::to_string(spec.points.size() - 1) + ")");
    const auto r = scenes::run_pool(spec, dir, 1, a.task);
    return r.failed > 0 ? 1 : 0;
  }
  if (a.out.empty()) throw scenes::SceneError("--out", "(none)", "is required for a sweep");
  scenes::SlurmOptions slurm;
  slurm.partition = a.partition;
  slurm.time = a.time;
  slurm.array_limit = a.array_limit;
  slurm.lines = a.sbatch_lines;
  if (!slurm.lines.empty() && !a.slurm && !a.submit)
    throw scenes::SceneError("--sbatch-line", scenes::show(scenes::Json(slurm.lines.front())),
                             "needs --slurm or --submit");
  scenes::check_slurm_options(slurm);
  const SweepSpec spec = plan(a);
  const fs::path dir = a.out;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  const scenes::SweepLock lock(dir);  // held (by the points too) until the sweep has ended
  claim_folder(spec, dir);
  std::cout << "conform sweep " << spec.scene << ": " << spec.points.size() << " points into "
            << dir.string() << "\n"
            << std::flush;
  if (a.slurm || a.submit) {
    const fs::path file =
        scenes::write_sbatch(spec, dir, fs::read_symlink("/proc/self/exe"), slurm);
    std::cout << "job array: " << file.string() << "\n";
    // Slurm refuses array indices at or above MaxArraySize, 1001 unless the site raised it.
    if (spec.points.size() > 1001)
      std::cout << "note: " << spec.points.size() << " tasks: Slurm's default MaxArraySize is "
                << "1001 (`scontrol show config | grep MaxArraySize` shows the cluster's)\n";
    if (!a.submit) {
      std::cout << "submit it with: sbatch " << word(file.string()) << "\n";
      return 0;
    }
    std::cout << "submitted job " << scenes::submit_sbatch(file) << "\n"
              << "when it is done: conform sweep --gather " << word(file.parent_path().string())
              << "\n";
    return 0;
  }
  const int jobs = a.jobs > 0 ? a.jobs : int(std::max(1u, std::thread::hardware_concurrency()));
  scenes::run_pool(spec, dir, jobs, -1, lock.fd());
  return gather(spec, dir);
}

}  // namespace

void register_sweep(CLI::App& app, Context& context) {
  auto* cmd = app.add_subcommand(
      "sweep", "Run a scene over a grid of settings (locally or as a Slurm job array)");
  auto a = std::make_shared<SweepArgs>();
  cmd->add_option("TARGET", a->target,
                  "scene (built-in name or JSON file); the sweep folder with --task/--gather")
      ->required();
  cmd->add_option("--grid", a->grids, "KEY=V1,V2,...: one axis of the Cartesian product")
      ->allow_extra_args(false);
  cmd->add_option("--zip", a->zips, "KEY=V1,V2,...: axes that advance together (same length)")
      ->allow_extra_args(false);
  cmd->add_option("--set", a->sets, "KEY=VALUE for every run")->allow_extra_args(false);
  cmd->add_option("--repeat", a->repeat, "runs of each point, with seeds 1..N")
      ->check(CLI::Range(1, scenes::kMaxSweepPoints));
  cmd->add_option("--steps", a->steps, "steps of every run (default: the scene's)")
      ->check(CLI::Range(1, scenes::kMaxSteps));
  cmd->add_option("--out", a->out, "the sweep folder (runs/, sweep.csv, sweep.json, plots/)");
  cmd->add_option("--jobs", a->jobs, "runs at once (default: the cores)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--plot", a->plot, "METRIC[,METRIC]: metrics to plot (default: headline)")
      ->delimiter(',');
  cmd->add_flag("--slurm", a->slurm, "write DIR/sweep.sbatch (a job array) instead of running");
  cmd->add_option("--partition", a->partition, "Slurm partition");
  cmd->add_option("--time", a->time, "Slurm time limit per task (e.g. 00:10:00)");
  cmd->add_option("--array-limit", a->array_limit, "most array tasks running at once")
      ->check(CLI::Range(0, scenes::kMaxSweepPoints));
  cmd->add_option("--sbatch-line", a->sbatch_lines,
                  "an #SBATCH directive for the job array, e.g. --mem=4G (repeatable)")
      ->allow_extra_args(false);
  cmd->add_flag("--submit", a->submit, "submit sweep.sbatch with sbatch (implies --slurm)");
  cmd->add_option("--task", a->task, "run point N of the sweep in folder TARGET")
      ->check(CLI::Range(0, scenes::kMaxSweepPoints));
  cmd->add_flag("--gather", a->gather, "build the table and plots of folder TARGET");
  cmd->callback([&context, a]() {
    try {
      context.exit_code = sweep_main(*a);
    } catch (const scenes::SweepInterrupted& e) {
      std::cerr << "conform sweep: " << e.what()
                << ": the points it stopped are missing; the same command resumes the sweep\n";
      context.exit_code = 128 + e.signal();
    } catch (const scenes::SweepBusy& e) {
      std::cerr << "conform sweep: " << e.what() << " (nothing run)\n";
      context.exit_code = 2;
    } catch (const scenes::SceneError& e) {
      std::cerr << "conform sweep: " << a->target << ": " << e.what() << " (nothing run)\n";
      context.exit_code = 2;
    } catch (const std::exception& e) {
      std::cerr << "conform sweep: " << e.what() << "\n";
      context.exit_code = 2;
    }
  });
}

}  // namespace conform::cli
