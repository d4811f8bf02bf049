#include "render/render_settings.hpp"

namespace conform::scenes {

namespace {

RenderCamera read_camera(Reader& r) {
  RenderCamera c;
  // A position or target of 1 km is no longer a camera aimed at a body of a metre.
  constexpr double kFar = 1000;
  c.has_target = r.has("target");
  c.has_position = r.has("position");
  c.has_up = r.has("up");
  c.target = r.vec3("target", c.target, kFar);
  c.position = r.vec3("position", c.position, kFar);
  c.up = r.vec3("up", c.up, kFar);
  if (c.has_up && c.up.norm() < 1e-9) r.fail("up", Json::array({0, 0, 0}), "must not be zero");
  if (c.has_target && c.has_position && (c.target - c.position).norm() < 1e-9)
    r.fail("position", Json::array({c.position.x(), c.position.y(), c.position.z()}),
           "must differ from camera.target");
  c.view_angle = r.number("view_angle", c.view_angle, 1, 120);
  c.framing = r.number("framing", c.framing, 1, 1000);
  r.finish();
  return c;
}

}  // namespace

RenderSettings read_render(Reader& root) {
  RenderSettings s;
  if (root.is_boolean("render")) {
    s.enabled = s.glb = root.boolean("render", true);
    return s;
  }
  Reader r = root.object("render");
  s.enabled = r.boolean("enabled", true);
  s.glb = r.boolean("glb", true);
  s.pictures = r.integer("pictures", s.pictures, 1, 1000);
  s.width = r.integer("width", s.width, 16, 4096);
  s.height = r.integer("height", s.height, 16, 4096);
  s.scalar = r.text("scalar", s.scalar, {"stretch", "gap"});
  s.video = r.text("video", s.video, {"gif", "mp4", "none"});
  s.range = r.number("range", s.range, 0, 10);
  s.perspective = r.boolean("perspective", s.perspective);
  Reader cam = r.object("camera");
  s.camera = read_camera(cam);
  r.finish();
  return s;
}

}  // namespace conform::scenes
