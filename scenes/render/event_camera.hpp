// The camera of a run's pictures, aimed at the event: it looks at the wound's (or cut's)
// vertices along the skin's outward normal there, turned so that the wound's long axis lies
// across the picture, from far enough that the picture spans `framing` times the wound. The
// scene's render.camera overrides any part of it. One camera serves every panel and frame.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>

#include "render/frame_snapshot.hpp"
#include "render/render_settings.hpp"

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
/// strip_camera's view angle, degrees: it depends only on the panel's angle and aspect.
double strip_view_angle(double panel_view_angle, double aspect, double max_parallax_deg = 1);

/// A camera's view frame, scaled: the eye at the origin, the target at (0, 0, -1), the
/// picture's right along +x and its up along +y. A surface written in it and seen through
/// `view_frame_camera(view_angle)` gives the picture the camera gives of the surface itself: a
/// rigid motion and a uniform scale about the eye move no pixel of a perspective picture, and
/// f3d's lights follow its camera. So a render's camera is known before the event is, and f3d
/// can start up while the scene simulates (f3d_render.hpp).
struct ViewFrame {
  Eigen::Matrix3d rotation;  // rows: right, up, backwards (from the target to the eye)
  Eigen::Vector3d eye;
  double scale;  // 1 / the eye's distance to the target
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    return scale * (rotation * (x - eye));
  }
};
ViewFrame view_frame(const Camera& c);
Camera view_frame_camera(double view_angle);

}  // namespace conform::scenes
