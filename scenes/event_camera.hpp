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

/// One render of several panels side by side: each panel's surface moved by `offset(k)` and
/// all seen by one camera, `camera`, whose picture is `panels` times as wide as one panel's.
/// It is the panel camera moved back along its view and narrowed to the same framing at the
/// target (a telephoto), far enough that neighbouring panels are seen at most
/// `max_parallax_deg` apart; each panel then looks as through the panel camera, with that
/// much less perspective. One f3d start-up (0.3 s of CPU) then serves a whole frame.
struct StripCamera {
  Camera camera;
  Eigen::Vector3d step;  // from one panel's place to the next one's, along the picture's right
  Eigen::Vector3d offset(int k, int panels) const { return (k - 0.5 * (panels - 1)) * step; }
};
StripCamera strip_camera(const Camera& panel, double aspect, double max_parallax_deg = 1);

}  // namespace conform::scenes
