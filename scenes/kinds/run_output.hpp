// What a scene run writes into its folder: metrics.csv (a time series), summary.json (settings,
// version, timings, final metrics), frames (PLY), PNG plots drawn by gnuplot from the CSV and,
// with outputs.vtk, the ParaView series of the body's frames (vtk/).
// The folder is created only when the run starts, i.e. after the scene parsed.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "base/progress.hpp"
#include "base/scene_config.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "render/frame_snapshot.hpp"
#include "render/plots.hpp"
#include "render/render_settings.hpp"

namespace conform::bullet {
class SkinnedSoftBody;
}

namespace conform::scenes {

/// Common settings every scene reads (physics, outputs, seed, length).
/// The most steps a run may take (duration / dt or --steps): 10^8 keeps every step count and
/// step index in an int, and is over a day of wall time even at 1 ms a step.
inline constexpr int kMaxSteps = 100000000;

/// The largest gravity a scene may set, m/s² (about 100 g).
inline constexpr double kMaxGravity = 1000;

struct CommonSettings {
  std::string name;  // scene name (built-in name or file stem)
  std::string kind;  // the scene's "scene" key
  std::uint64_t seed = 1;
  double dt = 1.0 / 60.0;  // one step, s
  int substeps = 4;        // internal substeps per step
  int solver_iterations = 10;
  Eigen::Vector3d gravity{0, -9.81, 0};
  int steps = 0;          // total steps (duration / dt, or --steps)
  int metrics_every = 1;  // steps between metric rows
  int frames_every = 0;   // steps between PLY frames (0: first and last only)
  bool plots = true;
  bool vtk = false;  // the ParaView series: vtk/*.vtu and vtk/series.pvd (render/vtk_series.hpp)
  int threads = 1;   // OpenMP threads (0: OpenMP's default)
  RenderSettings render{};  // pictures, video and run.glb (render_settings.hpp)
};

class PictureRenderer;
class GltfSequence;
class VtkSeries;

/// One run's surface in a picture: its name (the panel's title), its mesh and its wound.
struct PicturePanel {
  std::string name;
  const mesh::SkinnedMesh* mesh = nullptr;
  Lips lips{};
  std::string caption;  // under the panel: its headline number ("largest gap 13.24 mm")
};

class RunOutput {
 public:
  using Clock = std::chrono::steady_clock;

  /// Creates `dir` (and dir/frames). Throws std::runtime_error when it cannot.
  RunOutput(std::filesystem::path dir, const CommonSettings& common);
  ~RunOutput();

  const std::filesystem::path& dir() const { return dir_; }

  /// A CSV file in the run folder with the given header; rows are appended with row().
  class Csv {
   public:
    /// A value that does not exist at this row (the hand piece before the cut): written as an
    /// empty field, never as 0.
    static constexpr double kAbsent = std::numeric_limits<double>::quiet_NaN();
    Csv(const std::filesystem::path& path, std::vector<std::string> columns);
    void row(std::span<const double> values);
    std::size_t columns() const { return columns_.size(); }

   private:
    std::ofstream out_;
    std::vector<std::string> columns_;
  };
  Csv& metrics() { return *metrics_; }
  void open_metrics(std::vector<std::string> columns);
  Csv open_csv(const std::string& file, std::vector<std::string> columns);

  /// Writes frames/NAME_STEP.ply (positions of `mesh`, all faces or `faces`).
  void frame(const std::string& name, int step, const mesh::SkinnedMesh& mesh,
             std::span<const std::int32_t> faces = {});
  int frames_written() const { return frames_; }

  /// A frame of the simulated body: frames/NAME_STEP.ply (frame()) and, with outputs.vtk, its
  /// vertex fields for the ParaView series (kinds/body_fields.hpp). `lips` is the wound's, null
  /// when the scene makes none (the series then has no gap). Call it after body.sync_mesh().
  void body_frame(const std::string& name, int step, const bullet::SkinnedSoftBody& body,
                  const Lips* lips = nullptr);

  /// Offers a picture of this step: the panels side by side, rendered when the run finishes
  /// (render_frames.hpp; a no-op with "render": false). Offer every step (offers_pictures()):
  /// the pictures go where the wound changes. A `frame_step` (one written by frame()) is also a
  /// frame of run.glb.
  void picture(int step, const std::vector<PicturePanel>& panels, bool frame_step);
  /// Whether picture() renders anything: without pictures, offering other steps than frames is
  /// wasted work.
  bool offers_pictures() const { return pictures_ != nullptr; }
  /// Whether `step` is one of the run's frames (outputs.frames_every, and the last step).
  bool frame_step(int step) const;

  /// Progress on stderr (progress.hpp): a bar on a terminal, plain lines otherwise.
  void progress(int step, int steps);

  void add_plot(Plot plot) { plots_.push_back(std::move(plot)); }

  /// Draws the plots, writes summary.json (atomically) and returns its path. `settings` is the
  /// resolved scene, `metrics` the final metrics, `timings` extra timing entries; the wall time
  /// per simulated second and per step (of the stepping loop, `loop_seconds` long) are added.
  std::filesystem::path finish(const Json& settings, Json metrics, Json timings, int steps,
                               double simulated_seconds, double loop_seconds);
  /// What finish() did not produce that the run promised (a plot gnuplot failed to draw, a
  /// render, picture or video): summary.json's "failures"; the run then exits 1.
  const std::vector<std::string>& failures() const { return failures_; }
  /// A warning the run goes on with (a body's material_warnings): printed on stderr and kept in
  /// summary.json's "warnings".
  void warn(const std::string& message);
  /// Each of the body's material_warnings.
  void warn_material(const bullet::SkinnedSoftBody& body);

 private:
  /// Draws the plots (each series that is 0 throughout left out, a sentence in `notes`); their
  /// report for summary.json.
  Json draw_run_plots(Json& notes);
  /// The pictures (started at t0, while plots took plots_ms), the video and run.glb; their
  /// report for summary.json.
  Json finish_render(Clock::time_point t0, double plots_ms, double loop_seconds, int steps);

  std::filesystem::path dir_;
  CommonSettings common_;
  Clock::time_point start_;
  std::chrono::system_clock::time_point started_at_;  // for the summary's provenance
  std::clock_t cpu_start_;
  std::unique_ptr<Csv> metrics_;
  std::vector<Plot> plots_;
  std::unique_ptr<PictureRenderer> pictures_;
  std::unique_ptr<GltfSequence> gltf_;
  std::unique_ptr<VtkSeries> vtk_;
  int frames_ = 0;
  double offer_ms_ = 0;  // in picture(): snapshots taken in the stepping loop
  std::unique_ptr<Progress> progress_;
  std::vector<std::string> failures_, warnings_;
};

/// Reads the common keys (scene, seed, duration, physics, outputs) of a scene object.
CommonSettings read_common(Reader& root, const std::string& name, double default_duration,
                           int steps_override);

}  // namespace conform::scenes
