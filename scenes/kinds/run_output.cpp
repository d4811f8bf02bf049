#include "kinds/run_output.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>

#include "base/child_process.hpp"
#include "base/finite_json.hpp"
#include "base/interrupt.hpp"
#include "conform/bullet/convert.hpp"
#include "conform/io/mesh_export.hpp"
#include "conform/version.hpp"
#include "kinds/output_caps.hpp"
#include "kinds/provenance.hpp"
#include "render/gltf_sequence.hpp"
#include "render/render_frames.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

CommonSettings read_common(Reader& root, const std::string& name, double default_duration,
                           int steps_override) {
  CommonSettings c;
  c.name = name;
  c.kind = root.text("scene", "");
  root.text("description", "");
  c.seed = static_cast<std::uint64_t>(root.integer("seed", 1, 0, 2147483647));
  // One thread by default: the scenes' meshes are a few thousand vertices, where OpenMP's
  // fork/join costs more than it saves (and ruins timings on a loaded machine).
  c.threads = root.integer("threads", 1, 0, 1024);
  const double duration = root.number("duration", default_duration, 1e-6, 1e5);
  Reader physics = root.object("physics");
  c.dt = physics.number("dt", c.dt, 1e-5, 0.1);
  c.substeps = physics.integer("substeps", c.substeps, 1, 1000);
  c.solver_iterations = physics.integer("solver_iterations", c.solver_iterations, 1, 1000);
  // At most 100 g: -1e300 is finite but made every body's motion non-finite (and exited 0).
  c.gravity = physics.vec3("gravity", c.gravity, kMaxGravity);
  // Physics keys a scene kind may read later stay unread here; the kind finishes the object.
  physics.finish();
  Reader outputs = root.object("outputs");
  c.metrics_every = outputs.integer("metrics_every", 1, 1, 1000000);
  c.frames_every = outputs.integer("frames_every", 0, 0, 1000000);
  c.plots = outputs.boolean("plots", true);
  outputs.finish();
  c.render = read_render(root);
  // In double first: int(duration / dt) overflowed to a 1-step run that reported success.
  const double steps = std::max(1.0, std::round(duration / c.dt));
  if (steps_override <= 0 && steps > kMaxSteps)
    throw SceneError("duration", show(Json(duration)),
                     "with physics.dt = " + show(Json(c.dt)) + " gives " +
                         std::to_string(static_cast<long long>(steps)) +
                         " steps, more than the limit of " + std::to_string(kMaxSteps));
  c.steps = steps_override > 0 ? steps_override : static_cast<int>(steps);
  check_output_caps(c);
  return c;
}

RunOutput::Csv::Csv(const fs::path& path, std::vector<std::string> columns)
    : out_(path), columns_(std::move(columns)) {
  if (!out_) throw std::runtime_error("cannot write " + path.string());
  for (std::size_t i = 0; i < columns_.size(); ++i) out_ << (i ? "," : "") << columns_[i];
  out_ << "\n";
}

void RunOutput::Csv::row(std::span<const double> values) {
  if (values.size() != columns_.size())
    throw std::logic_error("metrics row has " + std::to_string(values.size()) + " values, not " +
                           std::to_string(columns_.size()));
  char buf[32];
  for (std::size_t i = 0; i < values.size(); ++i) {
    // %.9g keeps the file deterministic and exact enough to compare runs.
    std::snprintf(buf, sizeof buf, "%.9g", values[i]);
    out_ << (i ? "," : "") << buf;
  }
  out_ << "\n";
}

RunOutput::RunOutput(fs::path dir, const CommonSettings& common)
    : dir_(std::move(dir)),
      common_(common),
      start_(Clock::now()),
      started_at_(std::chrono::system_clock::now()),
      cpu_start_(std::clock()) {
  std::error_code ec;
  fs::create_directories(dir_ / "frames", ec);
  if (ec)
    throw std::runtime_error("cannot create " + (dir_ / "frames").string() + ": " + ec.message());
  if (common_.render.enabled)
    pictures_ = std::make_unique<PictureRenderer>(common_.render, dir_, common_.name);
  if (common_.render.glb) gltf_ = std::make_unique<GltfSequence>();
}

RunOutput::~RunOutput() = default;

void RunOutput::open_metrics(std::vector<std::string> columns) {
  metrics_ = std::make_unique<Csv>(dir_ / "metrics.csv", std::move(columns));
}

RunOutput::Csv RunOutput::open_csv(const std::string& file, std::vector<std::string> columns) {
  return Csv(dir_ / file, std::move(columns));
}

void RunOutput::frame(const std::string& name, int step, const mesh::SkinnedMesh& mesh,
                      std::span<const std::int32_t> faces) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%06d.ply", step);
  io::write_mesh(dir_ / "frames" / (name + buf), mesh, {}, faces);
  ++frames_;
  // A piece (a subset of faces) is not a frame of the sequence: its whole mesh is.
  if (gltf_ && faces.empty())
    gltf_->add(snapshot(name, step, step * common_.dt, mesh, {}, common_.render.scalar));
}

void RunOutput::picture(int step, const std::vector<PicturePanel>& panels) {
  if (!pictures_ && !gltf_) return;
  std::vector<FrameSnapshot> shots;
  for (const auto& p : panels)
    shots.push_back(
        snapshot(p.name, step, step * common_.dt, *p.mesh, p.lips, common_.render.scalar));
  if (gltf_)
    for (const auto& s : shots) gltf_->add(s);
  if (pictures_) pictures_->add(std::move(shots));
}

Json RunOutput::finish_render(Clock::time_point t0, double plots_ms, double loop_seconds,
                              int steps) {
  Json report = Json::object();
  if (pictures_) report = pictures_->finish();
  // What the pictures add to the run's wall time: the plots drawn meanwhile are not theirs.
  const double pictures_ms = std::max(
      0.0, std::chrono::duration<double, std::milli>(Clock::now() - t0).count() - plots_ms);
  if (gltf_ && gltf_->size() > 0) {
    const auto t1 = Clock::now();
    gltf_->write(dir_ / "run.glb", common_.render.scalar, common_.render.range);
    report["glb"] = "run.glb";
    report["glb_frames"] = gltf_->size();
    report["glb_ms"] = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
  }
  // Rendering against simulating, in the same run: one picture against one step.
  const std::size_t n = report.contains("pictures") ? report["pictures"].size() : 0;
  const double step_ms = steps > 0 ? 1e3 * loop_seconds / steps : 0.0;
  report["render_ms_total"] = pictures_ms;
  report["render_ms_per_picture"] = n > 0 ? pictures_ms / double(n) : 0.0;
  report["sim_ms_per_step"] = step_ms;
  report["render_picture_per_sim_step"] =
      n > 0 && step_ms > 0 ? pictures_ms / double(n) / step_ms : 0.0;
  return report;
}

void RunOutput::progress(int step, int steps) {
  check_interrupt();  // every scene reports each step: where a stop signal ends the loop
  if (!progress_) progress_ = std::make_unique<Progress>(common_.name, "step", steps);
  progress_->update(step);
}

namespace {

// A gnuplot string constant holding `s` as it is: single-quoted, where gnuplot substitutes no
// backquoted command and no escape (a quote is doubled). A line break would end the command:
// it becomes a space.
std::string quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') out += '\'';
    out += c == '\n' || c == '\r' ? ' ' : c;
  }
  return out + "'";
}

void write_axes(std::ostream& gp, const Plot& p) {
  gp << "set title " << quote(p.title) << "\n"
     << "set xlabel " << quote(p.xlabel) << "\n"
     << "set ylabel " << quote(p.ylabel) << "\n"
     << "plot ";
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const auto& s = p.series[i];
    gp << (i ? ", \\\n     " : "") << quote(s.file) << " using " << quote(s.x) << ":" << quote(s.y)
       << " with " << s.style << " lw 2 title " << quote(s.title);
  }
  gp << "\n";
}

}  // namespace

namespace {

bool write_plot_script(const fs::path& dir, const Plot& plot, std::string& problem) {
  const fs::path script = dir / (plot.name + ".gp");
  std::ofstream gp(script);
  if (!gp) {
    problem = "cannot write " + script.string();
    return false;
  }
  const int panels = std::max<int>(1, static_cast<int>(plot.panels.size()));
  // `reset` first: the scripts run one after the other in one gnuplot (draw_plots).
  gp << "# Drawn by conform from the CSV files beside it: gnuplot " << plot.name << ".gp\n"
     << "reset\nset terminal pngcairo size " << (panels > 1 ? 600 * panels : 1000)
     << ",600 enhanced font 'sans,11'\n"
     << "set output " << quote(plot.name + ".png") << "\n"
     << "set datafile separator ','\n"
     << "set grid\nset key top left\n";
  if (plot.panels.empty()) {
    write_axes(gp, plot);
  } else {
    gp << "set multiplot layout 1," << panels << " title " << quote(plot.title) << "\n";
    for (const auto& p : plot.panels) write_axes(gp, p);
    gp << "unset multiplot\n";
  }
  gp << "unset output\n";  // the PNG is complete before the next script starts
  if (!gp) problem = "cannot write " + script.string();
  return bool(gp);
}

}  // namespace

std::vector<std::string> draw_plots(const fs::path& dir, const std::vector<Plot>& plots) {
  std::vector<std::string> problems(plots.size());
  std::vector<std::string> args = {"gnuplot"};
  for (std::size_t i = 0; i < plots.size(); ++i)
    if (write_plot_script(dir, plots[i], problems[i])) args.push_back(plots[i].name + ".gp");
  if (args.size() == 1) return problems;
  // One gnuplot for all: its start-up (fonts, cairo) is most of a small plot's cost.
  const fs::path log = fs::absolute(dir / "plots.log");
  ChildOptions options;
  options.log = log.string();
  options.dir = fs::absolute(dir).string();
  ChildProcess gnuplot(args, options);
  const bool ok = gnuplot.running() && gnuplot.wait() == 0;
  check_interrupt();
  // gnuplot stops at the first failing script: what came before it was drawn.
  for (std::size_t i = 0; i < plots.size(); ++i)
    if (problems[i].empty() && (!ok || !fs::exists(dir / (plots[i].name + ".png"))))
      problems[i] = "gnuplot failed (see plots.log in the output folder)";
  if (ok) fs::remove(log);
  return problems;
}

bool have_gnuplot() {
  return have_tool("gnuplot");
}

fs::path RunOutput::finish(const Json& settings, Json metrics, Json timings, int steps,
                           double simulated_seconds, double loop_seconds) {
  metrics_.reset();  // flush metrics.csv before gnuplot reads it
  check_interrupt();
  if (progress_) progress_->finish();
  if (const std::string bad = first_non_finite(metrics, ""); !bad.empty())
    throw std::runtime_error("metric " + bad +
                             " is NaN or infinite: the simulation went non-finite");
  // The renderer's f3d processes run while gnuplot draws the plots (both mostly wait).
  const auto render_start = Clock::now();
  if (pictures_) pictures_->start();
  Json plots = Json::object();
  const auto plots_start = Clock::now();
  if (common_.plots) {
    std::vector<std::string> problems(
        plots_.size(), "gnuplot is not installed (scripts/deps.sh installs gnuplot-nox)");
    const bool drawn = have_gnuplot();
    if (drawn) problems = draw_plots(dir_, plots_);
    for (std::size_t i = 0; i < plots_.size(); ++i) {
      plots[plots_[i].name] =
          problems[i].empty() ? plots_[i].name + ".png" : "not drawn: " + problems[i];
      // A missing gnuplot is a note; a gnuplot that failed, a failure of the run.
      if (drawn && !problems[i].empty())
        failures_.push_back("plot " + plots_[i].name + " not drawn: " + problems[i]);
    }
  }
  const double plots_ms =
      std::chrono::duration<double, std::milli>(Clock::now() - plots_start).count();
  const Json render = finish_render(render_start, plots_ms, loop_seconds, steps);
  for (const auto& f : render.value("failures", Json::array())) failures_.push_back(f);
  const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
  Json summary;
  summary["scene"] = common_.name;
  summary["kind"] = common_.kind;
  summary["version"] = conform::version();
  summary["bullet_precision"] = bullet::bullet_precision();
  summary["seed"] = common_.seed;
  summary["provenance"] = provenance(started_at_);
  summary["settings"] = settings;
  // The per-second and per-step figures are of the stepping loop (physics, skinning, topology,
  // metrics, frames); wall_s also counts loading, setup and plotting.
  timings["wall_s"] = wall;
  timings["loop_s"] = loop_seconds;
  timings["steps"] = steps;
  timings["simulated_s"] = simulated_seconds;
  timings["wall_per_simulated_second_s"] =
      simulated_seconds > 0 ? loop_seconds / simulated_seconds : 0.0;
  timings["wall_per_step_ms"] = steps > 0 ? 1e3 * loop_seconds / steps : 0.0;
  timings["real_time_factor"] = loop_seconds > 0 ? simulated_seconds / loop_seconds : 0.0;
  // Process CPU time (all of the run, setup included): steadier than wall time on a busy
  // machine, where the wall figures above include time spent waiting for a core.
  const double cpu = double(std::clock() - cpu_start_) / CLOCKS_PER_SEC;
  timings["cpu_s"] = cpu;
  timings["cpu_per_simulated_second_s"] = simulated_seconds > 0 ? cpu / simulated_seconds : 0.0;
  summary["timings"] = timings;
  summary["metrics"] = metrics;
  summary["frames"] = frames_;
  summary["plots"] = plots;
  summary["render"] = render;
  summary["failures"] = failures_;
  // Settings, timings and what the scene added: JSON would hold NaN or inf as null.
  require_finite(summary, "summary.json");
  const fs::path path = dir_ / "summary.json", tmp = dir_ / ".summary.json.tmp";
  {
    std::ofstream out(tmp);
    out << summary.dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
  return path;
}

}  // namespace conform::scenes
