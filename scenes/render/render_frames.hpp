// Pictures of a run: chosen frames rendered by a real renderer (Debian's f3d, on a virtual X
// display of conform's own when there is none, virtual_display.hpp), the runs of one frame side
// by side with the same camera (event_camera.hpp), coloured by a scalar (colour_scale.hpp) with
// a colour bar and a title (composed with cairo, picture_compose.hpp), the inside of the skin as
// a wound bed, and a short video of the pictures (ffmpeg).
//
// The wound bed and the panels side by side: strip_mesh.hpp. The last frame's f3d starts with
// the run's first frame and waits for its surface while the scene simulates (f3d_render.hpp).
//
// Written into the run folder:
//   pictures/step_STEP.png        the side-by-side picture of one frame
//   pictures/panels/strip_STEP.png the frame's panels side by side as f3d rendered them
//                                 (NAME_STEP.png, one per panel, with render.perspective)
//   pictures/render.sh            the f3d commands that made the panels, for the record: conform
//                                 runs f3d itself, from argument vectors (their PLY inputs are
//                                 removed once rendered)
//   run.gif or run.mp4            the pictures in turn (when there are 2 or more)
// A missing tool (f3d, Xvfb, ffmpeg) is a warning, never a failed run; a render, picture or video
// that a present tool failed to make is a failure of the run (the report's "failures").
// No helper is run through a shell. A stop signal (interrupt.hpp) ends the renders and throws.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "base/scene_config.hpp"
#include "render/f3d_render.hpp"
#include "render/frame_snapshot.hpp"
#include "render/picture_choice.hpp"
#include "render/render_settings.hpp"
#include "render/virtual_display.hpp"

namespace conform::scenes {

class PictureRenderer {
 public:
  /// A run of `run_steps` steps: its pictures go in `dir`/pictures.
  PictureRenderer(RenderSettings settings, std::filesystem::path dir, std::string title,
                  int run_steps);

  /// Offers one frame: its panels, left to right (e.g. physics, geometric). Any step may be
  /// offered; the frames kept are those where the wound changes (picture_choice.hpp). Every
  /// frame must have as many panels as the first.
  void add(std::vector<FrameSnapshot> panels);
  std::size_t offered() const { return offered_; }
  /// Whether a frame of `step` whose panels' wounds (FrameSnapshot::wound) are these is worth
  /// offering (PictureCandidates::worth_offering); the run's last step always is.
  bool wants(int step, const std::vector<double>& wounds);

  /// Starts rendering the chosen frames (f3d runs in the background).
  void start();
  /// Waits for the renders (starting them if start() was not called), composes the pictures
  /// and the video; returns what was written, timings and warnings (for summary.json).
  /// Warnings also go to stderr.
  Json finish();

  PictureRenderer(const PictureRenderer&) = delete;
  PictureRenderer& operator=(const PictureRenderer&) = delete;
  ~PictureRenderer();

 private:
  void prestart(std::size_t panels);
  struct Pending;  // a render under way
  struct Input;    // one render's surface
  std::vector<Input> inputs(const Pending& p) const;
  bool feed_prestarted(std::size_t k, const Input& in, Pending& p);
  void queue_render(Pending& p, const Input& in, bool retry) const;
  static bool job_done(Pending& p, std::size_t k, int status);
  static void launch_renders(Pending& p);

  RenderSettings settings_;
  std::filesystem::path dir_;
  std::string title_;
  PictureCandidates candidates_{16};
  std::size_t offered_ = 0;
  int run_steps_ = 0;
  bool prestart_tried_ = false;
  std::unique_ptr<Pending> pending_;
  bool have_f3d_ = false;
  std::unique_ptr<VirtualDisplay> display_;  // when conform has no display of its own
  std::vector<std::unique_ptr<PrestartedRender>> prestarted_;  // the last frame's renders
  bool started_ = false;
};

/// True when `tool` is an executable file in a folder of PATH (searched here, not by a shell).
bool have_tool(const std::string& tool);

}  // namespace conform::scenes
