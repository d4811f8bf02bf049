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

std::uint8_t byte(double c) {
  return static_cast<std::uint8_t>(std::lround(255 * std::clamp(c, 0.0, 1.0)));
}

// A skin's thickness for the inner layer: half a percent of the surface's size (3 mm on the
// arm), thin enough not to show from outside, thick enough not to fight the outer layer for
// depth.
double bed_depth(const FrameSnapshot& s) {
  if (s.positions.cols() == 0) return 0;
  const Eigen::Vector3d lo = s.positions.rowwise().minCoeff(),
                        hi = s.positions.rowwise().maxCoeff();
  return 0.005 * (hi - lo).norm();
}

// The render input: the coloured surface, then the wound bed (binary little-endian PLY, which
// f3d reads with its colours as the "RGB" array).
void write_panel_ply(const fs::path& path, const FrameSnapshot& s, const ColourScale& scale) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  const auto nv = static_cast<std::size_t>(s.positions.cols());
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << 2 * nv
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nelement face "
      << 2 * s.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  const double depth = bed_depth(s);
  const auto vertex = [&](const Eigen::Vector3d& x, const Rgb& c) {
    const float f[3] = {float(x.x()), float(x.y()), float(x.z())};
    const std::uint8_t rgb[3] = {byte(c[0]), byte(c[1]), byte(c[2])};
    out.write(reinterpret_cast<const char*>(f), sizeof f);
    out.write(reinterpret_cast<const char*>(rgb), sizeof rgb);
  };
  for (std::size_t v = 0; v < nv; ++v) vertex(s.positions.col(Eigen::Index(v)), scale(s.scalar[v]));
  for (std::size_t v = 0; v < nv; ++v)
    vertex(s.positions.col(Eigen::Index(v)) - depth * s.normals.col(Eigen::Index(v)), kWoundBed);
  const auto face = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {a, b, c};
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(idx), sizeof idx);
  };
  for (const auto& f : s.faces) face(f[0], f[1], f[2]);
  const auto off = static_cast<std::int32_t>(nv);
  for (const auto& f : s.faces) face(f[0] + off, f[2] + off, f[1] + off);  // facing inwards
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string f3d_command(const std::string& ply, const std::string& png, const RenderSettings& r,
                        const Camera& c) {
  // --dry-run: no user configuration file, so every run renders alike (and it halves f3d's
  // start-up). Direct colours (--comp=-2) are the scale's, baked into the PLY.
  return "f3d --dry-run --quiet " + sq(ply) + " --output " + sq(png) + " --resolution " +
         std::to_string(r.width) + "," + std::to_string(r.height) +
         " --scalars=RGB --comp=-2 --fxaa --bg-color 1,1,1" + " --camera-position " +
         csv3(c.position) + " --camera-focal-point " + csv3(c.target) + " --camera-view-up " +
         csv3(c.up) + " --camera-view-angle " + std::to_string(c.view_angle) + " > " +
         sq(png + ".log") + " 2>&1";
}

struct Layout {
  int width, height, panels, total_w, total_h;
  double sx(double px) const { return px / total_w; }
  double sy(double px) const { return px / total_h; }
};

void compose_frame(std::ostream& gp, const std::vector<FrameSnapshot>& frame, const Layout& l,
                   const ColourScale& scale, const std::string& title, const std::string& scalar) {
  char buf[2048];
  gp << "reset\n" << scale.gnuplot_palette() << "\n";
  std::snprintf(buf, sizeof buf, "set cbrange [%.9g:%.9g]\nunset colorbox\n", scale.min, scale.max);
  gp << buf << "set output '" << stem("step", frame.front().step) << ".png'\n";
  std::snprintf(buf, sizeof buf, "%s, t = %.2f s, coloured by %s", title.c_str(),
                frame.front().time, scalar.c_str());
  gp << "set multiplot title \"" << buf << "\"\n"
     << "unset border\nunset xtics\nunset ytics\n";
  for (int i = 0; i < l.panels; ++i) {
    const auto& p = frame[static_cast<std::size_t>(i)];
    std::snprintf(buf, sizeof buf,
                  "set lmargin at screen %.6f\nset rmargin at screen %.6f\n"
                  "set bmargin at screen 0\nset tmargin at screen %.6f\n"
                  "set xrange [0:%d]\nset yrange [0:%d]\nset title '%s' offset 0,-0.6\n",
                  l.sx(i * l.width), l.sx((i + 1) * l.width), l.sy(l.height), l.width - 1,
                  l.height - 1, p.name.c_str());
    gp << buf << "plot 'panels/" << stem(p.name, p.step)
       << ".png' binary filetype=png with rgbimage notitle\n";
  }
  // The colour bar: a gradient strip with the values on its right, and the wound bed's swatch.
  const double x0 = l.panels * l.width + 20, x1 = x0 + 22;
  std::snprintf(buf, sizeof buf,
                "set lmargin at screen %.6f\nset rmargin at screen %.6f\n"
                "set bmargin at screen %.6f\nset tmargin at screen %.6f\n"
                "unset title\nset border\nset xrange [0:1]\nset yrange [0:1]\n"
                "set y2range [%.9g:%.9g]\nset y2tics\nset y2label \"%s\"\n"
                "set samples 256,256\nset isosamples 256,256\n"
                "set object 1 rect from screen %.6f,screen %.6f to screen %.6f,screen %.6f "
                "fc rgb '#%02x%02x%02x' fs solid noborder\n"
                "set label 1 'wound bed' at screen %.6f,screen %.6f\n",
                l.sx(x0), l.sx(x1), l.sy(0.22 * l.height), l.sy(0.92 * l.height), scale.min,
                scale.max, scale.label.c_str(), l.sx(x0), l.sy(0.06 * l.height), l.sx(x1),
                l.sy(0.06 * l.height + 18), byte(kWoundBed[0]), byte(kWoundBed[1]),
                byte(kWoundBed[2]), l.sx(x0), l.sy(0.06 * l.height - 14));
  gp << buf;
  // The strip is sampled on [0, 1] and mapped onto the range: '++' over a small range such as
  // [-0.15, 0.15] came out in 8 flat bands.
  std::snprintf(buf, sizeof buf, "plot '++' using 1:2:(%.9g + %.9g * $2) with image notitle\n",
                scale.min, scale.max - scale.min);
  gp << buf << "unset multiplot\n";
}

}  // namespace

bool have_tool(const std::string& tool) {
  return std::system(("command -v " + tool + " > /dev/null 2>&1").c_str()) == 0;
}

PictureRenderer::PictureRenderer(RenderSettings settings, fs::path dir, std::string title)
    : settings_(std::move(settings)), dir_(std::move(dir)), title_(std::move(title)) {}

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
// and spends most of its time starting), under xvfb-run when there is no display. Returns the
// running script (to pclose), or nullptr.
FILE* launch_panels(const fs::path& pics, const std::vector<std::string>& jobs,
                    const RenderSettings& r, Json& report) {
  const unsigned cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  {
    std::ofstream sh(pics / "render.sh");
    sh << "#!/bin/sh\n# Drawn by conform: the f3d renders of this run's panels (from the PLY "
          "inputs, removed once rendered).\ncd \"$(dirname \"$0\")\" || exit 1\n";
    for (std::size_t i = 0; i < jobs.size(); ++i)
      sh << jobs[i] << " &\n" << ((i + 1) % cores == 0 || i + 1 == jobs.size() ? "wait\n" : "");
    if (!sh) {
      warn(report, "cannot write " + (pics / "render.sh").string());
      return nullptr;
    }
  }
  const char* display = std::getenv("DISPLAY");
  std::string cmd = "sh " + sq((pics / "render.sh").string());
  if (!display || !*display) {
    if (!have_tool("xvfb-run")) {
      warn(report, "no display and no xvfb-run (scripts/deps.sh installs xvfb): no pictures");
      return nullptr;
    }
    const int w = std::max(r.width, 1280), h = std::max(r.height, 1024);
    cmd = "xvfb-run -a -s " +
          sq("-screen 0 " + std::to_string(w) + "x" + std::to_string(h) + "x24") + " " + cmd;
  }
  cmd += " > " + sq((pics / "render.log").string()) + " 2>&1";
  FILE* running = ::popen(cmd.c_str(), "r");
  if (!running) warn(report, "cannot start the render script " + (pics / "render.sh").string());
  return running;
}

bool compose(const fs::path& pics, const std::vector<std::vector<FrameSnapshot>>& frames,
             const RenderSettings& r, const ColourScale& scale, const std::string& title,
             Json& report) {
  if (!have_tool("gnuplot")) {
    warn(report, "gnuplot is not installed: the panels are not put side by side");
    return false;
  }
  const int panels = static_cast<int>(frames.front().size());
  const Layout l{r.width, r.height, panels, panels * r.width + 170, r.height + 60};
  {
    std::ofstream gp(pics / "compose.gp");
    gp << "# Drawn by conform: the side-by-side pictures from panels/*.png: gnuplot compose.gp\n"
       << "set terminal pngcairo size " << l.total_w << "," << l.total_h
       << " noenhanced font 'sans,12'\n";
    for (const auto& f : frames) compose_frame(gp, f, l, scale, title, r.scalar);
  }
  const std::string cmd = "cd " + sq(pics.string()) + " && gnuplot compose.gp > compose.log 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    warn(report, "gnuplot failed (see " + (pics / "compose.log").string() + ")");
    return false;
  }
  fs::remove(pics / "compose.log");
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
  p.camera =
      aim_camera(p.frames.back(), settings_.camera, double(settings_.width) / settings_.height);
  p.pics = dir_ / "pictures";
  fs::create_directories(p.pics / "panels");
  std::vector<std::string> jobs;
  for (const auto& f : p.frames)
    for (const auto& panel : f) {
      const std::string s = "panels/" + stem(panel.name, panel.step);
      write_panel_ply(p.pics / (s + ".ply"), panel, p.scale);
      p.inputs.push_back(p.pics / (s + ".ply"));
      jobs.push_back(f3d_command(s + ".ply", s + ".png", settings_, p.camera));
    }
  p.panels = jobs.size();
  p.t_render = Clock::now();
  p.running = launch_panels(p.pics, jobs, settings_, p.report);
}

Json PictureRenderer::finish() {
  if (!started_) start();
  Pending& p = *pending_;
  Json& report = p.report;
  if (!p.running) return report;
  const int rc = ::pclose(p.running);
  p.running = nullptr;
  if (rc != 0)
    warn(report, "the render script failed (see " + (p.pics / "render.log").string() + ")");
  const double render_ms = ms_since(p.t_render);
  for (const auto& in : p.inputs) fs::remove(in);
  std::size_t missing = 0;
  for (const auto& f : p.frames)
    for (const auto& panel : f) {
      const fs::path png = p.pics / "panels" / (stem(panel.name, panel.step) + ".png");
      if (!fs::exists(png)) ++missing;
      fs::remove(png.string() + ".log");
    }
  if (missing > 0) {
    warn(report, std::to_string(missing) + " panels were not rendered (see " +
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
  report["scale"] = {{"scalar", settings_.scalar}, {"min", p.scale.min}, {"max", p.scale.max}};
  // f3d's wall time includes the plots drawn meanwhile (RunOutput::finish).
  report["timings"] = {
      {"panels", p.panels},         {"f3d_ms_per_panel", render_ms / double(p.panels)},
      {"compose_ms", compose_ms},   {"video_ms", ms_since(t_video)},
      {"total_ms", ms_since(p.t0)}, {"ms_per_picture", ms_since(p.t0) / double(p.frames.size())}};
  return report;
}

}  // namespace conform::scenes
