#include "render_frames.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <thread>

#include "colour_scale.hpp"
#include "event_camera.hpp"
#include "picture_compose.hpp"
#include "progress.hpp"
#include "strip_mesh.hpp"
#include "virtual_display.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// For sh: single quotes, with any single quote closed, escaped and reopened.
std::string sq(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string csv3(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", v.x(), v.y(), v.z());
  return buf;
}

std::string stem(const std::string& prefix, int step) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "_%06d", step);
  return prefix + buf;
}

std::string f3d_command(const std::string& ply, const std::string& png, int width, int height,
                        const Camera& c) {
  char angle[32];
  std::snprintf(angle, sizeof angle, "%.9g", c.view_angle);
  // --dry-run: no user configuration file, so every run renders alike (and it halves f3d's
  // start-up). Direct colours (--comp=-2) are the scale's, baked into the PLY.
  return "f3d --dry-run --quiet " + sq(ply) + " --output " + sq(png) + " --resolution " +
         std::to_string(width) + "," + std::to_string(height) +
         " --scalars=RGB --comp=-2 --fxaa --bg-color 1,1,1" + " --camera-position " +
         csv3(c.position) + " --camera-focal-point " + csv3(c.target) + " --camera-view-up " +
         csv3(c.up) + " --camera-view-angle " + angle + " > " + sq(png + ".log") + " 2>&1";
}

}  // namespace

bool have_tool(const std::string& tool) {
  return std::system(("command -v " + tool + " > /dev/null 2>&1").c_str()) == 0;
}

PictureRenderer::PictureRenderer(RenderSettings settings, fs::path dir, std::string title)
    : settings_(std::move(settings)), dir_(std::move(dir)), title_(std::move(title)) {
  // Without a display of our own, a virtual one starts now, while the scene simulates.
  const char* own = std::getenv("DISPLAY");
  if ((!own || !*own) && have_tool("f3d"))
    display_ = std::make_unique<VirtualDisplay>(std::max(settings_.width, 1280),
                                                std::max(settings_.height, 1024));
}

void PictureRenderer::add(std::vector<FrameSnapshot> panels) {
  if (!panels.empty()) frames_.push_back(std::move(panels));
}

// At most `pictures` frames: the last one and the others evenly spaced before it.
std::vector<std::size_t> PictureRenderer::chosen() const {
  const std::size_t m = frames_.size(), n = std::min<std::size_t>(m, settings_.pictures);
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < n; ++k)
    out.push_back(n == 1 ? m - 1 : (m - 1) - (n - 1 - k) * (m - 1) / (n - 1));
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

void warn(Json& report, const std::string& message) {
  std::cerr << "conform run: warning: " << message << "\n";
  report["warnings"].push_back(message);
}

// Starts the f3d jobs of render.sh, as many at once as there are cores (f3d is single-threaded
// and spends most of its time starting), on `display` (":N") when conform has none of its own.
// Returns the running script (to pclose), or nullptr.
FILE* launch_panels(const fs::path& pics, const std::vector<std::string>& jobs,
                    const std::string& display, Json& report) {
  const unsigned cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  {
    std::ofstream sh(pics / "render.sh");
    sh << "#!/bin/sh\n# Drawn by conform: the f3d renders of this run's panels (from the PLY "
          "inputs, removed once rendered).\ncd \"$(dirname \"$0\")\" || exit 1\n";
    for (std::size_t i = 0; i < jobs.size(); ++i)
      // A line on stdout per rendered frame: conform's progress counts them.
      sh << "{ " << jobs[i] << " && echo rendered; } &\n"
         << ((i + 1) % cores == 0 || i + 1 == jobs.size() ? "wait\n" : "");
    if (!sh) {
      warn(report, "cannot write " + (pics / "render.sh").string());
      return nullptr;
    }
  }
  std::string cmd = "sh " + sq((pics / "render.sh").string());
  if (!display.empty()) cmd = "DISPLAY=" + sq(display) + " " + cmd;
  cmd += " 2> " + sq((pics / "render.log").string());
  FILE* running = ::popen(cmd.c_str(), "r");
  if (!running) warn(report, "cannot start the render script " + (pics / "render.sh").string());
  return running;
}

// The f3d renders of a frame, left to right, as paths under pictures/ without extension: one
// strip of all its panels, or with "perspective" one per panel.
std::vector<std::string> renders_of(const std::vector<FrameSnapshot>& frame, bool perspective) {
  if (!perspective) return {"panels/" + stem("strip", frame.front().step)};
  std::vector<std::string> out;
  for (const auto& p : frame) out.push_back("panels/" + stem(p.name, p.step));
  return out;
}

std::size_t jobs_count(const std::vector<std::vector<FrameSnapshot>>& frames, bool perspective) {
  std::size_t n = 0;
  for (const auto& f : frames) n += renders_of(f, perspective).size();
  return n;
}

// The side-by-side pictures (picture_compose.hpp), one per chosen frame.
bool compose(const fs::path& pics, const std::vector<std::vector<FrameSnapshot>>& frames,
             const RenderSettings& r, const ColourScale& scale, const std::string& title,
             Json& report) {
  char buf[512];
  try {
    for (const auto& frame : frames) {
      const int step = frame.front().step;
      std::vector<std::string> names;
      for (const auto& p : frame) names.push_back(p.name);
      std::snprintf(buf, sizeof buf, "%s, t = %.2f s, coloured by %s", title.c_str(),
                    frame.front().time, r.scalar.c_str());
      std::vector<fs::path> renders;
      for (const auto& name : renders_of(frame, r.perspective))
        renders.push_back(pics / (name + ".png"));
      compose_picture(pics / (stem("step", step) + ".png"), renders, names, r.width, r.height, buf,
                      scale);
    }
  } catch (const std::exception& e) {
    warn(report, e.what());
    return false;
  }
  return true;
}

void make_video(const fs::path& dir, const RenderSettings& r, Json& report) {
  if (!have_tool("ffmpeg")) {
    warn(report, "ffmpeg is not installed (scripts/deps.sh installs it): no video");
    return;
  }
  const std::string out = r.video == "mp4" ? "run.mp4" : "run.gif";
  // Two pictures a second; the GIF gets its own palette, the MP4 even sizes for yuv420p.
  const std::string filter =
      r.video == "mp4" ? "-vf 'scale=trunc(iw/2)*2:trunc(ih/2)*2' -c:v libx264 -pix_fmt yuv420p"
                       : "-vf 'split[a][b];[a]palettegen[p];[b][p]paletteuse'";
  const std::string cmd = "cd " + sq(dir.string()) +
                          " && ffmpeg -y -loglevel error -framerate 2 -pattern_type glob -i "
                          "'pictures/step_*.png' " +
                          filter + " " + out + " > pictures/video.log 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    warn(report, "ffmpeg failed (see " + (dir / "pictures/video.log").string() + ")");
    return;
  }
  fs::remove(dir / "pictures/video.log");
  report["video"] = out;
}

Json camera_json(const Camera& c) {
  const auto v = [](const Eigen::Vector3d& x) { return Json::array({x.x(), x.y(), x.z()}); };
  return {{"position", v(c.position)},
          {"target", v(c.target)},
          {"up", v(c.up)},
          {"view_angle", c.view_angle},
          {"aimed_at", c.how}};
}

}  // namespace

struct PictureRenderer::Pending {
  Json report = {{"pictures", Json::array()}, {"warnings", Json::array()}};
  Clock::time_point t0 = Clock::now(), t_render = Clock::now();
  std::vector<std::vector<FrameSnapshot>> frames;
  ColourScale scale{};
  Camera camera{};
  StripCamera strip{};
  fs::path pics;
  std::vector<fs::path> inputs;
  std::size_t panels = 0;
  FILE* running = nullptr;
};

PictureRenderer::~PictureRenderer() {
  if (pending_ && pending_->running) ::pclose(pending_->running);
}

void PictureRenderer::start() {
  started_ = true;
  pending_ = std::make_unique<Pending>();
  Pending& p = *pending_;
  if (frames_.empty()) return;
  if (!have_tool("f3d")) {
    warn(p.report,
         "f3d is not installed (scripts/deps.sh installs f3d, xvfb, ffmpeg): no pictures");
    return;
  }
  for (const auto i : chosen()) p.frames.push_back(frames_[i]);
  std::vector<double> values;
  for (const auto& f : p.frames)
    for (const auto& panel : f)
      values.insert(values.end(), panel.scalar.begin(), panel.scalar.end());
  p.scale = make_scale(settings_.scalar, values, settings_.range);
  const double aspect = double(settings_.width) / settings_.height;
  p.camera = aim_camera(p.frames.back(), settings_.camera, aspect);
  p.strip = strip_camera(p.camera, aspect);
  const StripCamera& strip = p.strip;
  p.pics = dir_ / "pictures";
  fs::create_directories(p.pics / "panels");
  // One f3d render per frame, of all its panels side by side (strip_camera), or one per panel
  // through the camera itself.
  const StripCamera alone{p.camera, Eigen::Vector3d::Zero()};
  std::vector<std::string> jobs;
  for (const auto& f : p.frames) {
    const auto names = renders_of(f, settings_.perspective);
    for (std::size_t k = 0; k < names.size(); ++k) {
      const std::string& s = names[k];
      const bool one = names.size() > 1;  // a panel alone
      const std::vector<FrameSnapshot> panels = one ? std::vector{f[k]} : f;
      write_strip_ply(p.pics / (s + ".ply"), panels, p.scale, one ? alone : strip, aspect);
      p.inputs.push_back(p.pics / (s + ".ply"));
      const int width = settings_.width * static_cast<int>(panels.size());
      jobs.push_back(f3d_command(s + ".ply", s + ".png", width, settings_.height,
                                 one ? p.camera : strip.camera));
    }
    p.panels += f.size();
  }
  p.t_render = Clock::now();
  std::string display;
  if (display_) {
    display = display_->display();
    if (display.empty()) {
      warn(p.report, display_->error() + ": no pictures");
      return;
    }
  }
  p.running = launch_panels(p.pics, jobs, display, p.report);
}

Json PictureRenderer::finish() {
  if (!started_) start();
  Pending& p = *pending_;
  Json& report = p.report;
  if (!p.running) return report;
  Progress bar("pictures", "render", long(jobs_count(p.frames, settings_.perspective)));
  char line[64];
  for (long rendered = 1; std::fgets(line, sizeof line, p.running); ++rendered)
    bar.update(rendered);
  const int rc = ::pclose(p.running);
  bar.finish();
  p.running = nullptr;
  if (rc != 0)
    warn(report, "the render script failed (see " + (p.pics / "render.log").string() + ")");
  const double render_ms = ms_since(p.t_render);
  for (const auto& in : p.inputs) fs::remove(in);
  std::size_t missing = 0;
  for (const auto& f : p.frames)
    for (const auto& name : renders_of(f, settings_.perspective)) {
      const fs::path png = p.pics / (name + ".png");
      if (!fs::exists(png)) ++missing;
      fs::remove(png.string() + ".log");
    }
  if (missing > 0) {
    warn(report, std::to_string(missing) + " renders are missing (see " +
                     (p.pics / "render.log").string() + ")");
    return report;
  }
  fs::remove(p.pics / "render.log");
  const auto t_compose = Clock::now();
  if (compose(p.pics, p.frames, settings_, p.scale, title_, report))
    for (const auto& f : p.frames)
      report["pictures"].push_back("pictures/" + stem("step", f.front().step) + ".png");
  const double compose_ms = ms_since(t_compose);
  const auto t_video = Clock::now();
  if (settings_.video != "none" && report["pictures"].size() >= 2)
    make_video(dir_, settings_, report);
  report["camera"] = camera_json(p.camera);
  if (!settings_.perspective)
    report["strip_camera"] = camera_json(p.strip.camera);  // the one f3d used (strip_camera)
  report["scale"] = {{"scalar", settings_.scalar}, {"min", p.scale.min}, {"max", p.scale.max}};
  // f3d's wall time includes the plots drawn meanwhile (RunOutput::finish).
  report["timings"] = {{"panels", p.panels},
                       {"f3d_renders", jobs_count(p.frames, settings_.perspective)},
                       {"f3d_ms_per_panel", render_ms / double(p.panels)},
                       {"compose_ms", compose_ms},
                       {"video_ms", ms_since(t_video)},
                       {"total_ms", ms_since(p.t0)},
                       {"ms_per_picture", ms_since(p.t0) / double(p.frames.size())}};
  return report;
}

}  // namespace conform::scenes
