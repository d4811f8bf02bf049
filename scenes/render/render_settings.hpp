// The scene's "render" key: pictures of the event (PNG, side by side), a short video and one
// glTF file of the whole sequence. `"render": false` (or `conform run --no-render`) turns all
// of it off; an object sets the details:
//   "render": { "enabled": true, "pictures": 1, "width": 640, "height": 480, "scalar": "stretch",
//               "video": "gif", "glb": true, "range": 0, "perspective": false,
//               "camera": { "target": [x,y,z], "position": [x,y,z], "up": [x,y,z],
//                           "view_angle": 30, "framing": 1.6 } }
// Without camera.target/position the camera frames the event (the wound's border) itself.
// "perspective": false renders a frame's panels in one f3d start-up, through a telephoto of the
// camera (event_camera.hpp, strip_camera): the same framing at the target, with less
// perspective; true renders each panel through the camera itself, at one f3d start-up (0.3 s of
// CPU) per panel.
#pragma once

#include <Eigen/Core>
#include <string>

#include "base/scene_config.hpp"

namespace conform::scenes {

struct RenderCamera {
  bool has_target = false, has_position = false, has_up = false;
  Eigen::Vector3d target{0, 0, 0}, position{0, 0, 0}, up{0, 1, 0};
  double view_angle = 30;  // degrees, vertical
  double framing = 1.6;    // the picture spans this many times the event's size
};

struct RenderSettings {
  bool enabled = true;             // pictures and video
  bool glb = true;                 // run.glb, the whole sequence
  int pictures = 1;                // the most pictures: where the wound changes (picture_choice.hpp)
  int width = 640, height = 480;   // one panel, pixels
  std::string scalar = "stretch";  // "stretch" (edge strain) or "gap" (width across the lips)
  std::string video = "gif";       // "gif", "mp4" or "none"
  double range = 0;                // colour range: +-range (stretch) or [0, range] (gap); 0: auto
  bool perspective = false;        // each panel through the camera itself (one render each)
  RenderCamera camera{};
};

/// Reads `render` from a scene object (a boolean or an object; absent: the defaults).
RenderSettings read_render(Reader& root);

}  // namespace conform::scenes
