#include "render/render_frames.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <thread>

#include "base/child_process.hpp"
#include "base/interrupt.hpp"
#include "base/progress.hpp"
#include "render/colour_scale.hpp"
#include "render/event_camera.hpp"
#include "render/f3d_render.hpp"
#include "render/picture_compose.hpp"
#include "render/strip_mesh.hpp"
#include "render/virtual_display.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// With "perspective" each panel of a frame is its own render, through the camera itself;
// otherwise, or with a single panel, the frame's panels are one strip (strip_camera).
bool each_panel_alone(bool perspective, std::size_t panels) {
  return perspective && panels > 1;
}

std::string stem(const std::string& prefix, int step) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "_%06d", step);
  return prefix + buf;
}

}  // namespace

bool have_tool(const std::string& tool) {
  // As execvp searches (ChildProcess): each folder of PATH, an empty entry being the current one.
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    const fs::path candidate = (folder.empty() ? fs::path(".") : fs::path(folder)) / tool;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

PictureRenderer::PictureRenderer(RenderSettings settings, fs::path dir, std::string title,
                                 int run_steps)
    : settings_(std::move(settings)),
      dir_(std::move(dir)),
      title_(std::move(title)),
      run_steps_(run_steps),
      have_f3d_(have_tool("f3d")) {
  // Without a display of our own, a virtual one starts now, while the scene simulates.
  const char* own = std::getenv("DISPLAY");
  if ((!own || !*own) && have_f3d_)
    display_ = std::make_unique<VirtualDisplay>(std::max(settings_.width, 1280),
                                                std::max(settings_.height, 1024));
}

namespace {

// What one offered frame holds, bytes: positions, normals, UVs, the scalar and the faces.
std::size_t frame_bytes(const std::vector<FrameSnapshot>& panels) {
  std::size_t bytes = 0;
  for (const auto& p : panels)
    bytes += sizeof(double) * (9 * static_cast<std::size_t>(p.positions.cols())) +
             sizeof(mesh::Face) * p.faces.size();
  return std::max<std::size_t>(bytes, 1);
}

}  // namespace

bool PictureRenderer::wants(int step, const std::vector<double>& wounds) {
  // The last frame's renders start with the first frame offered: f3d starts up while the scene
  // simulates (f3d_render.hpp). Every frame is expected to have as many panels as the first.
  if (!prestart_tried_ && have_f3d_ && !wounds.empty()) prestart(wounds.size());
  prestart_tried_ = true;
  // One picture is the last frame's: no other frame is worth a snapshot.
  if (step >= run_steps_) return true;
  return settings_.pictures > 1 && candidates_.worth_offering(step, wounds, run_steps_);
}

void PictureRenderer::add(std::vector<FrameSnapshot> panels) {
  if (panels.empty()) return;
  if (candidates_.empty()) {
    // Enough candidates to spread the pictures where the wound changes, within 256 MiB.
    const std::size_t wanted = std::clamp<std::size_t>(8 * settings_.pictures, 16, 128);
    const std::size_t fit =
        std::max<std::size_t>(8, (std::size_t(256) << 20) / frame_bytes(panels));
    candidates_ = PictureCandidates(std::min(wanted, fit));
    if (!prestart_tried_ && have_f3d_) prestart(panels.size());
    prestart_tried_ = true;
  }
  ++offered_;
  candidates_.add(std::move(panels));
}

// The renders of the last frame start now, while the scene simulates (f3d_render.hpp).
void PictureRenderer::prestart(std::size_t panels) {
  const fs::path dir = dir_ / "pictures" / "panels";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return;  // start() says why
  const double aspect = double(settings_.width) / settings_.height;
  const int n = static_cast<int>(panels);
  const bool one = each_panel_alone(settings_.perspective, panels);
  const double angle =
      one ? settings_.camera.view_angle : strip_view_angle(settings_.camera.view_angle, aspect);
  for (int k = 0; k < (one ? n : 1); ++k)
    prestarted_.push_back(std::make_unique<PrestartedRender>(
        dir, "last_" + std::to_string(k), settings_.width * (one ? 1 : n), settings_.height, angle,
        display_.get()));
}

namespace {

void warn(Json& report, const std::string& message) {
  std::cerr << "conform run: warning: " << message << "\n";
  report["warnings"].push_back(message);
}

// A run's failure to produce something it promised (a render, a picture, the video): recorded in
// summary.json, and the run exits 1 (RunOutput::failures).
void fail(Json& report, const std::string& message) {
  std::cerr << "conform run: error: " << message << "\n";
  report["failures"].push_back(message);
}

// `text` as comment lines of a script, whatever newlines it holds.
std::string comment(const std::string& text) {
  std::string out = "# ";
  for (const char c : text) out += c == '\n' ? std::string("\n# ") : std::string(1, c);
  return out + "\n";
}

// Writes render.sh, the record of the f3d renders of this run's panels: conform runs them itself,
// each from its argument vector. The script repeats them (every word single-quoted) and, as
// comments, the renders that started before their surface existed (`prestarted`).
bool write_render_record(const fs::path& pics, const std::vector<std::vector<std::string>>& jobs,
                         const std::vector<std::string>& names,
                         const std::vector<std::string>& prestarted) {
  std::ofstream sh(pics / "render.sh");
  sh << "#!/bin/sh\n# Drawn by conform: the f3d renders of this run's panels, as conform ran them "
        "(from the PLY inputs, removed once rendered).\ncd \"$(dirname \"$0\")\" || exit 1\n";
  for (const auto& job : prestarted)
    sh << "# Started while the scene simulated, reading its surface from a FIFO:\n" << comment(job);
  for (std::size_t i = 0; i < jobs.size(); ++i)
    sh << shell_words(jobs[i]) << " > " << shell_words({names[i] + ".png.log"}) << " 2>&1\n";
  return bool(sh);
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

// The length of a pixel at the camera's target: a panel's height spans 2 d tan(a/2) there, d the
// camera's distance and a its vertical view angle (a strip's camera, farther and narrower, frames
// the target alike: strip_camera).
double metres_per_pixel(const Camera& c, int height) {
  const double d = (c.position - c.target).norm();
  return 2 * d * std::tan(0.5 * c.view_angle * std::numbers::pi / 180) / height;
}

// The side-by-side pictures (picture_compose.hpp), one per chosen frame.
bool compose(const fs::path& pics, const std::vector<std::vector<FrameSnapshot>>& frames,
             const RenderSettings& r, const ColourScale& scale, const Camera& camera,
             const std::string& title, Json& report) {
  char buf[512];
  PictureText words;
  words.bar = scale_bar(metres_per_pixel(camera, r.height), kScaleBarPixels);
  report["scale_bar"] = {{"metres_per_pixel_at_target", words.bar.metres_per_pixel},
                         {"length_m", words.bar.length_m},
                         {"pixels", words.bar.pixels}};
  try {
    for (const auto& frame : frames) {
      const int step = frame.front().step;
      words.names.clear();
      words.captions.clear();
      for (const auto& p : frame) {
        words.names.push_back(p.name);
        words.captions.push_back(p.caption);
      }
      std::snprintf(buf, sizeof buf, "%s, t = %.2f s, coloured by %s", title.c_str(),
                    frame.front().time, r.scalar.c_str());
      words.title = buf;
      std::vector<fs::path> renders;
      for (const auto& name : renders_of(frame, r.perspective))
        renders.push_back(pics / (name + ".png"));
      compose_picture(pics / (stem("step", step) + ".png"), renders, words, r.width, r.height,
                      scale);
    }
  } catch (const std::exception& e) {
    fail(report, e.what());
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
  std::vector<std::string> args = {
      "ffmpeg", "-y", "-loglevel",          "error", "-framerate", "2", "-pattern_type",
      "glob",   "-i", "pictures/step_*.png"};
  if (r.video == "mp4")
    args.insert(args.end(), {"-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-c:v", "libx264",
                             "-pix_fmt", "yuv420p"});
  else
    args.insert(args.end(), {"-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse"});
  args.push_back(out);
  const fs::path log = fs::absolute(dir / "pictures" / "video.log");
  ChildOptions options;
  options.log = log.string();
  options.dir = fs::absolute(dir).string();
  ChildProcess ffmpeg(args, options);
  const int status = ffmpeg.running() ? ffmpeg.wait() : -1;
  check_interrupt();
  if (status != 0 || !fs::exists(dir / out)) {
    fail(report, "ffmpeg failed (exit " + std::to_string(status) + ", see " + log.string() + ")");
    return;
  }
  fs::remove(log);
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
  Json report = {
      {"pictures", Json::array()}, {"warnings", Json::array()}, {"failures", Json::array()}};
  Clock::time_point t0 = Clock::now(), t_render = Clock::now();
  std::vector<std::vector<FrameSnapshot>> frames;
  ColourScale scale{};
  Camera camera{};
  StripCamera strip{};
  fs::path pics;
  std::vector<fs::path> inputs;                                // the PLY files render.sh reads
  std::vector<std::pair<PrestartedRender*, std::size_t>> fed;  // and the input it took
  std::vector<Input> fed_inputs;  // kept to render anew if the early f3d fails
  std::size_t panels = 0;
  // The f3d renders run from here, at most `cores` at once (f3d is single-threaded and spends
  // most of its time starting), started by this thread (their parent-death signal follows it).
  std::vector<std::vector<std::string>> jobs;  // arguments, in pictures/
  std::vector<std::string> job_names;          // the render each makes
  std::vector<bool> retry;                     // whether a failed job is rendered again
  std::size_t next_job = 0;
  std::deque<ChildProcess> running;
  std::deque<std::size_t> running_jobs;  // the job each runs
  std::string display;                   // ":N" when conform has no display of its own
  std::size_t cores = 1;
};

// One f3d render's surface: a frame's panels, or one of them, in its camera's view frame.
struct PictureRenderer::Input {
  std::string name;  // under pictures/, without extension
  std::string ply;   // the PLY file's bytes
  int width;         // pixels
  double view_angle;
  bool last;  // of the last frame
};

PictureRenderer::~PictureRenderer() {
  pending_.reset();  // its renders stop before the display they draw on
}

void PictureRenderer::launch_renders(Pending& p) {
  while (p.running.size() < p.cores && p.next_job < p.jobs.size()) {
    const std::size_t k = p.next_job++;
    ChildOptions options;
    if (!p.display.empty()) options.env.push_back("DISPLAY=" + p.display);
    options.log = fs::absolute(p.pics / (p.job_names[k] + ".png.log")).string();
    options.dir = fs::absolute(p.pics).string();
    p.running.emplace_back(p.jobs[k], options);
    p.running_jobs.push_back(k);
  }
}

// A render of `in` by a new f3d, from its PLY file; a job that fails is rendered once more
// when `retry` (f3d under Xvfb now and then exits without a picture on a loaded machine).
void PictureRenderer::queue_render(Pending& p, const Input& in, bool retry) const {
  const fs::path ply = p.pics / (in.name + ".ply");
  std::ofstream(ply, std::ios::binary) << in.ply;
  p.inputs.push_back(ply);
  p.jobs.push_back(
      f3d_arguments(in.name + ".ply", in.name + ".png", in.width, settings_.height, in.view_angle));
  p.job_names.push_back(in.name);
  p.retry.push_back(retry);
}

// After job `k` ended with `status`: whether it made its picture; if not, and it may, it is
// queued again (the same arguments, noted in the report).
bool PictureRenderer::job_done(Pending& p, std::size_t k, int status) {
  if (status == 0 && fs::exists(p.pics / (p.job_names[k] + ".png"))) return true;
  if (!p.retry[k]) return false;
  p.report["notes"].push_back("the f3d render of " + p.job_names[k] + " failed (exit " +
                              std::to_string(status) + "): rendered again");
  p.jobs.push_back(p.jobs[k]);
  p.job_names.push_back(p.job_names[k]);
  p.retry.push_back(false);
  return false;
}

// Every render's surface: one strip per frame (strip_camera), or one per panel through the
// camera itself.
std::vector<PictureRenderer::Input> PictureRenderer::inputs(const Pending& p) const {
  const double aspect = double(settings_.width) / settings_.height;
  const StripCamera alone{p.camera, Eigen::Vector3d::Zero()};
  std::vector<Input> out;
  for (const auto& f : p.frames) {
    const auto names = renders_of(f, settings_.perspective);
    for (std::size_t k = 0; k < names.size(); ++k) {
      const bool one = each_panel_alone(settings_.perspective, f.size());
      const std::vector<FrameSnapshot> panels = one ? std::vector{f[k]} : f;
      const StripCamera& view = one ? alone : p.strip;
      out.push_back({names[k], strip_ply(panels, p.scale, view, aspect),
                     settings_.width * static_cast<int>(panels.size()), view.camera.view_angle,
                     &f == &p.frames.back()});
    }
  }
  return out;
}

void PictureRenderer::start() {
  started_ = true;
  pending_ = std::make_unique<Pending>();
  Pending& p = *pending_;
  if (candidates_.empty()) return;
  if (!have_f3d_) {
    warn(p.report,
         "f3d is not installed (scripts/deps.sh installs f3d, xvfb, ffmpeg): no pictures");
    return;
  }
  // Where the wound changes (picture_choice.hpp): the span, in summary.json's render.chosen.
  const PictureChoice choice = candidates_.choose(static_cast<std::size_t>(settings_.pictures));
  const auto& kept = candidates_.frames();
  for (const auto i : choice.frames) p.frames.push_back(kept[i]);
  p.report["chosen"] = {{"by", choice.by_wound ? "wound" : "even"},
                        {"from_step", kept[choice.from].front().step},
                        {"settled_step", kept[choice.settled].front().step},
                        {"offered", offered_},
                        {"kept", kept.size()}};
  std::vector<double> values;
  for (const auto& f : p.frames)
    for (const auto& panel : f)
      values.insert(values.end(), panel.scalar.begin(), panel.scalar.end());
  p.scale = make_scale(settings_.scalar, values, settings_.range);
  const double aspect = double(settings_.width) / settings_.height;
  p.camera = aim_camera(p.frames.back(), settings_.camera, aspect);
  p.strip = strip_camera(p.camera, aspect);
  p.pics = dir_ / "pictures";
  fs::create_directories(p.pics / "panels");
  for (const auto& f : p.frames) p.panels += f.size();
  std::string display;
  if (display_) {
    display = display_->display();
    if (display.empty()) {
      warn(p.report, display_->error() + ": no pictures");
      return;
    }
  }
  p.t_render = Clock::now();
  std::vector<std::string> comments;
  std::size_t last = 0;  // the last frame's renders so far
  for (const auto& in : inputs(p)) {
    if (in.last && feed_prestarted(last++, in, p)) {
      comments.push_back(shell_words(prestarted_[last - 1]->arguments()));
      continue;
    }
    queue_render(p, in, true);
  }
  if (!write_render_record(p.pics, p.jobs, p.job_names, comments))
    fail(p.report, "cannot write " + (p.pics / "render.sh").string());
  p.display = display;
  p.cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  launch_renders(p);
}

// Hands render `in`, the k-th of the last frame, to the f3d started for it, when that one
// renders the same size through the same view angle and is still there to take it (otherwise
// it is rendered anew).
bool PictureRenderer::feed_prestarted(std::size_t k, const Input& in, Pending& p) {
  if (k >= prestarted_.size()) return false;
  PrestartedRender& r = *prestarted_[k];
  if (r.width() != in.width || std::abs(r.view_angle() - in.view_angle) > 1e-9) return false;
  std::string problem;
  if (!r.feed(in.ply, problem)) {
    p.report["notes"].push_back("the f3d started early for " + in.name +
                                " could not take its surface (" + problem + "): rendered anew");
    return false;
  }
  p.fed.emplace_back(&r, p.fed_inputs.size());
  p.fed_inputs.push_back(in);
  return true;
}

Json PictureRenderer::finish() {
  if (!started_) start();
  check_interrupt();
  Pending& p = *pending_;
  Json& report = p.report;
  if (p.jobs.empty() && p.fed.empty()) return report;
  Progress bar("pictures", "render", long(jobs_count(p.frames, settings_.perspective)));
  long rendered = 0;
  for (const auto& [render, k] : p.fed) {
    std::string problem;
    const bool ok = render->finish(problem);
    check_interrupt();
    const Input& in = p.fed_inputs[k];
    if (ok) {
      fs::rename(render->png(), p.pics / (in.name + ".png"));
      bar.update(++rendered);
      continue;
    }
    report["notes"].push_back("the f3d started early for " + in.name + " failed (" + problem +
                              "): rendered anew");
    queue_render(p, in, true);
  }
  launch_renders(p);
  while (!p.running.empty()) {
    const int status = p.running.front().wait();
    check_interrupt();
    const std::size_t k = p.running_jobs.front();
    p.running.pop_front();
    p.running_jobs.pop_front();
    if (job_done(p, k, status)) bar.update(++rendered);
    launch_renders(p);
  }
  bar.finish();
  const double render_ms = ms_since(p.t_render);
  for (const auto& in : p.inputs) fs::remove(in);
  std::size_t missing = 0;
  std::string first_missing;
  for (const auto& f : p.frames)
    for (const auto& name : renders_of(f, settings_.perspective)) {
      const fs::path png = p.pics / (name + ".png");
      if (fs::exists(png)) {
        fs::remove(png.string() + ".log");
      } else if (missing++ == 0) {
        first_missing = png.string() + ".log";
      }
    }
  if (missing > 0) {
    fail(report, std::to_string(missing) + " of " +
                     std::to_string(jobs_count(p.frames, settings_.perspective)) +
                     " renders are missing (see " + first_missing + ")");
    return report;
  }
  const auto t_compose = Clock::now();
  if (compose(p.pics, p.frames, settings_, p.scale, p.camera, title_, report))
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
                       {"f3d_started_early", p.fed.size()},
                       {"f3d_ms_per_panel", render_ms / double(p.panels)},
                       {"compose_ms", compose_ms},
                       {"video_ms", ms_since(t_video)},
                       {"total_ms", ms_since(p.t0)},
                       {"ms_per_picture", ms_since(p.t0) / double(p.frames.size())}};
  return report;
}

}  // namespace conform::scenes
