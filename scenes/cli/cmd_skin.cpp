// `conform skin`: pose a model (a file or the procedural arm) at a time or over frames of an
// animation with CGA skinning, and write the posed meshes in world space.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include "cli/commands.hpp"
#include "cli/model_pose.hpp"
#include "conform/io/import.hpp"
#include "conform/io/mesh_export.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/output_caps.hpp"

namespace conform::cli {
namespace {

struct SkinArgs {
  std::string model, animation, out, blend = "log", mode = "lbs";
  double time = 0;
  int frames = 0;
  int max_influences = 4;
  int threads = 0;
  double max_output_mib = scenes::kDefaultMaxOutputMib;
  bool strict_weights = false;
  io::IsolationLimits import_limits;
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// out.ply → out_0003.ply for frame 3 of several.
std::filesystem::path frame_path(const std::filesystem::path& out, int frame, int frames) {
  if (frames <= 1) return out;
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%04d", frame);
  std::filesystem::path p = out;
  p.replace_filename(out.stem().string() + buf + out.extension().string());
  return p;
}

// The frames written so far, removed unless the command completes (a failed pose or a full
// disk left them behind).
struct WrittenFrames {
  std::vector<std::filesystem::path> paths;
  ~WrittenFrames() {
    std::error_code ignored;
    for (const auto& p : paths) std::filesystem::remove(p, ignored);
  }
};

// Refuses, before anything is written, an output larger than `max_mib` in all: the size of one
// frame (encoded from the bind pose; exact for binary PLY, close for text) times the frames.
void check_output_size(const mesh::SkinnedMesh& mesh, const io::MeshExportOptions& options,
                       int frames, double max_mib) {
  const double frame_mib = double(io::mesh_file_size(mesh, options)) / 1048576.0;
  if (frame_mib * frames > max_mib) {
    std::ostringstream why;
    why << frames << " frames of " << frame_mib << " MiB would write " << frame_mib * frames
        << " MiB, more than --max-output-mib " << max_mib;
    throw std::invalid_argument(why.str());
  }
}

int run_skin(const SkinArgs& a, bool has_time, bool has_frames) {
  if (has_time == has_frames)
    throw std::invalid_argument("give exactly one of --time and --frames");
  if (has_frames && (a.frames < 1 || a.frames > scenes::kMaxFrames))
    throw std::invalid_argument("--frames " + std::to_string(a.frames) + " must be in [1, " +
                                std::to_string(scenes::kMaxFrames) + "]");
  if (a.max_influences < 1 || a.max_influences > 16)
    throw std::invalid_argument("--max-influences must be in [1, 16]");
  skin::Blend blend;
  if (!skin::parse_blend(a.blend, blend))
    throw std::invalid_argument("--blend must be linear or log");
  const auto mode = skin::parse_skin_mode(a.mode);
  if (!mode || (*mode != skin::SkinMode::cga && *mode != skin::SkinMode::versor))
    throw std::invalid_argument("--mode must be lbs or versor");
  io::MeshExportOptions out_options;
  std::string ext = std::filesystem::path(a.out).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".ply")
    out_options.format = io::MeshFormat::PlyBinary;
  else if (ext == ".obj")
    out_options.format = io::MeshFormat::Obj;
  else
    throw std::invalid_argument("--out must end in .ply or .obj");

  auto t0 = Clock::now();
  io::ImportOptions import_options;
  import_options.strict_weights = a.strict_weights;
  import_options.isolate = true;  // a corrupt file must not kill or corrupt the command
  import_options.isolation = a.import_limits;
  io::SkinnedModel model = io::load_model(a.model, import_options);
  const double load_ms = ms_since(t0);
  for (const auto& w : model.warnings)
    std::cerr << "warning: " << model.source << ": " << w << "\n";

  const skin::Animation* anim = nullptr;
  if (!a.animation.empty()) {
    anim = &find_animation_or_throw(model, a.animation);
  } else if (!model.animations.empty()) {
    anim = &model.animations.front();
  }

  t0 = Clock::now();
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences,
                                a.max_influences);
  skinner.set_threads(a.threads);
  const double setup_ms = ms_since(t0);

  const int frames = has_frames ? a.frames : 1;
  check_output_size(model.mesh, out_options, frames, a.max_output_mib);
  const double duration = anim ? anim->duration() : 0;
  skin::Pose pose = skin::Pose::rest(model.skeleton);
  std::vector<double> skin_ms;
  double write_ms = 0;
  WrittenFrames written;
  for (int f = 0; f < frames; ++f) {
    const double t = has_time ? a.time : (frames > 1 ? duration * f / (frames - 1) : 0.0);
    const auto ts = Clock::now();
    if (anim) anim->sample(model.skeleton, t, blend, pose);
    skinner.skin(pose, *mode);
    skinner.write(model.mesh.current);
    skin_ms.push_back(ms_since(ts));
    const auto tw = Clock::now();
    const auto path = frame_path(a.out, f, frames);
    io::write_mesh(path, model.mesh, out_options);
    written.paths.push_back(path);
    write_ms += ms_since(tw);
    if (frames > 1 && (f == 0 || f + 1 == frames))
      std::cout << "  frame " << f << " t=" << t << " s → " << path.string() << "\n";
  }
  written.paths.clear();  // complete: kept
  std::vector<double> sorted = skin_ms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::cout << "skinned " << model.source << ": " << model.mesh.vertex_count() << " vertices, "
            << model.mesh.face_count() << " faces, " << model.skeleton.bone_count() << " bones, "
            << skinner.influences().count << " influences, mode " << a.mode << ", blend " << a.blend
            << "\n"
            << "  animation: "
            << (anim ? "'" + anim->name + "' (" + std::to_string(duration) + " s)"
                     : std::string("none (bind pose)"))
            << "\n"
            << "  frames: " << frames << (frames == 1 ? " → " + a.out : std::string()) << "\n"
            << "  timing: load " << load_ms << " ms, setup " << setup_ms << " ms, pose+skin median "
            << median << " ms/frame (min " << sorted.front() << ", max " << sorted.back()
            << "), write " << write_ms << " ms\n";
  return 0;
}

}  // namespace

void register_skin(CLI::App& app, Context& context) {
  auto* cmd =
      app.add_subcommand("skin", "Pose a model with CGA skinning and write the posed mesh(es)");
  auto args = std::make_shared<SkinArgs>();
  cmd->add_option("MODEL", args->model, "model file (any format assimp reads) or arm[:N]")
      ->required();
  cmd->add_option("--animation", args->animation, "animation name or index (default: the first)");
  auto* time = cmd->add_option("--time", args->time, "time in seconds");
  auto* frames = cmd->add_option("--frames", args->frames,
                                 "N frames evenly over the animation (at most 10000)");
  time->excludes(frames);
  cmd->add_option("--blend", args->blend, "key interpolation: linear or log (default log)");
  cmd->add_option("--mode", args->mode, "lbs (eq 17) or versor (blend the versors; default lbs)");
  cmd->add_option("--max-influences", args->max_influences,
                  "largest influences used per vertex (default 4)");
  cmd->add_option("--threads", args->threads, "OpenMP threads (default: all)");
  cmd->add_option("--max-output-mib", args->max_output_mib,
                  "refuse, before writing, output larger than this in all, MiB (default 4096)")
      ->check(CLI::PositiveNumber);
  add_strict_weights(cmd, args->strict_weights);
  add_import_limits(cmd, args->import_limits);
  cmd->add_option("--out", args->out, "output .ply or .obj (with --frames: name_0000.ext, ...)")
      ->required();
  cmd->callback([&context, args, time, frames]() {
    try {
      context.exit_code = run_skin(*args, time->count() > 0, frames->count() > 0);
    } catch (const std::exception& e) {
      std::cerr << "conform skin: " << e.what() << "\n";
      context.exit_code = 1;
    }
  });
}

}  // namespace conform::cli
