#include "kinds/run_output.hpp"

#include "conform/bullet/skinned_soft_body.hpp"

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
#include "kinds/body_fields.hpp"
#include "kinds/output_caps.hpp"
#include "kinds/provenance.hpp"
#include "render/gltf_sequence.hpp"
#include "render/render_frames.hpp"
#include "render/vtk_series.hpp"

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
  c.vtk = outputs.boolean("vtk", false);
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
    // %.9g keeps the file deterministic and exact enough to compare runs; kAbsent (NaN) is an
    // empty field, which gnuplot, numpy's genfromtxt and pandas read as missing.
    if (std::isnan(values[i]))
      buf[0] = '\0';
    else
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
    pictures_ =
        std::make_unique<PictureRenderer>(common_.render, dir_, common_.name, common_.steps);
  if (common_.render.glb) gltf_ = std::make_unique<GltfSequence>();
  if (common_.vtk) vtk_ = std::make_unique<VtkSeries>(dir_);
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

void RunOutput::body_frame(const std::string& name, int step, const bullet::SkinnedSoftBody& body,
                           const Lips* lips) {
  frame(name, step, body.mesh());
  if (vtk_) vtk_->add(name, step, step * common_.dt, body_fields(body, lips));
}

bool RunOutput::frame_step(int step) const {
  return (common_.frames_every > 0 && step % common_.frames_every == 0) || step == common_.steps;
}

void RunOutput::picture(int step, const std::vector<PicturePanel>& panels, bool frame_step) {
  const auto t0 = Clock::now();
  // Only the frames worth a picture are snapshot (their wounds tell: picture_choice.hpp).
  bool wanted = false;
  if (pictures_) {
    std::vector<double> wounds;
    for (const auto& p : panels) wounds.push_back(largest_gap(p.mesh->current, p.lips));
    wanted = pictures_->wants(step, wounds);
  }
  if (wanted || (gltf_ && frame_step)) {
    std::vector<FrameSnapshot> shots;
    for (const auto& p : panels) {
      shots.push_back(
          snapshot(p.name, step, step * common_.dt, *p.mesh, p.lips, common_.render.scalar));
      shots.back().caption = p.caption;
    }
    if (gltf_ && frame_step)
      for (const auto& s : shots) gltf_->add(s);
    if (wanted) pictures_->add(std::move(shots));
  }
  offer_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
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
  // The snapshots offered during the loop (every step where pictures are made), part of it.
  report["offer_ms_total"] = offer_ms_;
  report["offer_ms_per_step"] = steps > 0 ? offer_ms_ / steps : 0.0;
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

Json RunOutput::draw_run_plots(Json& notes) {
  // A quantity that is 0 throughout gets a sentence, not a flat line (drop_zero_series).
  std::vector<Plot> to_draw;
  Json plots = Json::object();
  for (Plot& plot : plots_) {
    std::string dropped;
    for (const std::string& note : drop_zero_series(dir_, plot)) {
      notes.push_back(plot.name + ".png: " + note);
      dropped += (dropped.empty() ? "" : "; ") + note;
    }
    if (has_series(plot))
      to_draw.push_back(plot);
    else
      plots[plot.name] = "not drawn: " + dropped;
  }
  std::vector<std::string> problems(
      to_draw.size(), "gnuplot is not installed (scripts/deps.sh installs gnuplot-nox)");
  const bool drawn = have_gnuplot();
  if (drawn) problems = draw_plots(dir_, to_draw);
  for (std::size_t i = 0; i < to_draw.size(); ++i) {
    plots[to_draw[i].name] =
        problems[i].empty() ? to_draw[i].name + ".png" : "not drawn: " + problems[i];
    // A missing gnuplot is a note; a gnuplot that failed, a failure of the run.
    if (drawn && !problems[i].empty())
      failures_.push_back("plot " + to_draw[i].name + " not drawn: " + problems[i]);
  }
  return plots;
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
  Json plot_notes = Json::array();
  if (common_.plots) plots = draw_run_plots(plot_notes);
  const double plots_ms =
      std::chrono::duration<double, std::milli>(Clock::now() - plots_start).count();
  const Json render = finish_render(render_start, plots_ms, loop_seconds, steps);
  for (const auto& f : render.value("failures", Json::array())) failures_.push_back(f);
  Json vtk;
  if (vtk_) {
    const auto t1 = Clock::now();
    vtk = vtk_->finish();
    vtk["ms"] = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    for (const auto& f : vtk["failures"]) failures_.push_back(f);
  }
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
  if (!plot_notes.empty()) summary["plot_notes"] = plot_notes;
  summary["render"] = render;
  if (vtk_) summary["vtk"] = vtk;
  summary["failures"] = failures_;
  summary["warnings"] = warnings_;
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

void RunOutput::warn_material(const bullet::SkinnedSoftBody& body) {
  for (const std::string& w : body.material_warnings()) warn(w);
}

void RunOutput::warn(const std::string& message) {
  std::cerr << "warning: " << message << "\n";
  warnings_.push_back(message);
}

}  // namespace conform::scenes
