// Pictures of a run: chosen frames rendered by a real renderer (Debian's f3d, under a virtual
// X display from xvfb-run when there is no display), the runs of one frame side by side with
// the same camera (event_camera.hpp), coloured by a scalar (colour_scale.hpp) with a colour bar
// and a title (gnuplot composes them), the inside of the skin as a wound bed, and a short video
// of the pictures (ffmpeg).
//
// The wound bed: every panel's surface is drawn twice, as it is and as an inner layer moved a
// skin's thickness inwards with its faces turned (so that it faces the inside) in the wound
// bed's colour. From outside the skin hides it; through an open wound it is what one sees,
// instead of the far inner wall of a hollow limb.
//
// Written into the run folder:
//   pictures/step_STEP.png        the side-by-side picture of one frame
//   pictures/panels/NAME_STEP.png one run's panel as f3d rendered it
//   pictures/render.sh, compose.gp the scripts that made them (re-runnable by hand)
//   run.gif or run.mp4            the pictures in turn (when there are 2 or more)
// A missing tool (f3d, xvfb-run, gnuplot, ffmpeg) is a warning, never a failed run.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "frame_snapshot.hpp"
#include "render_settings.hpp"
#include "scene_config.hpp"

namespace conform::scenes {

class PictureRenderer {
 public:
  PictureRenderer(RenderSettings settings, std::filesystem::path dir, std::string title);

  /// Offers one frame: its panels, left to right (e.g. physics, geometric).
  void add(std::vector<FrameSnapshot> panels);
  std::size_t offered() const { return frames_.size(); }

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
  std::vector<std::size_t> chosen() const;
  struct Pending;  // a render under way

  RenderSettings settings_;
  std::filesystem::path dir_;
  std::string title_;
  std::vector<std::vector<FrameSnapshot>> frames_;
  std::unique_ptr<Pending> pending_;
  bool started_ = false;
};

/// True when `tool` is on PATH.
bool have_tool(const std::string& tool);

}  // namespace conform::scenes
