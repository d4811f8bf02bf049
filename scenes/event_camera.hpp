// The camera of a run's pictures, aimed at the event: it looks at the wound's (or cut's)
// vertices along the skin's outward normal there, turned so that the wound's long axis lies
// across the picture, from far enough that the picture spans `framing` times the wound. The
// scene's render.camera overrides any part of it. One camera serves every panel and frame.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>

#include "frame_snapshot.hpp"
#include "render_settings.hpp"

namespace conform::scenes {

struct Camera {
  Eigen::Vector3d position, target, up;
  double view_angle = 30;  // degrees, vertical
  std::string how;         // "event", "mesh" (no event vertices: the whole surface) or "scene"
};

/// The camera for these panels (one frame, every run), from their focus vertices.
Camera aim_camera(std::span<const FrameSnapshot> panels, const RenderCamera& settings,
                  double aspect);

}  // namespace conform::scenes
