// A sweep as written to DIR/sweep.json: the scene, the fixed overrides, the axes, the points
// and the metrics to plot. Every later step (the local pool, `--task N DIR` on a cluster node,
// `--gather DIR`) reads the sweep back from this one file, so the tasks share no other state.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep/sweep_grid.hpp"

namespace conform::scenes {

struct SweepSpec {
  std::string command;            // the command line that made the sweep
  std::string version;            // conform's version
  std::string scene;              // built-in name or absolute path of the scene file
  std::string kind;               // the scene's kind (from parsing it)
  int steps = 0;                  // --steps of every run (0: the scene's own)
  std::vector<std::string> sets;  // fixed --set assignments, before each point's own
  std::vector<SweepAxis> axes;
  int repeat = 1;
  std::vector<std::string> plot;  // metrics to plot (keys of summary.json's "metrics")
  std::vector<SweepPoint> points;

  /// The arguments of the point's `conform run` (after the program name).
  std::vector<std::string> run_arguments(const SweepPoint& p,
                                         const std::filesystem::path& out) const;
};

/// DIR/runs/NNNNN: the folder of point `index`.
std::filesystem::path point_dir(const std::filesystem::path& dir, int index);

Json to_json(const SweepSpec& spec);
/// Reads DIR/sweep.json. Throws std::runtime_error naming the file and the problem.
SweepSpec read_spec(const std::filesystem::path& dir);
/// Writes DIR/sweep.json atomically (a temporary file renamed over it).
void write_spec(const std::filesystem::path& dir, const SweepSpec& spec);

/// Parses the scene of every point exactly as `conform run` would (load_scene with the same
/// --set assignments and --steps), so a bad key or value is refused before anything runs.
/// Fills spec.kind. Throws SceneError, its message prefixed with the point's values.
void validate_points(SweepSpec& spec);

/// Whether `a` and `b` describe the same runs (scene, steps, sets, points): a sweep may resume
/// into a folder only when they do.
bool same_runs(const SweepSpec& a, const SweepSpec& b);

}  // namespace conform::scenes
