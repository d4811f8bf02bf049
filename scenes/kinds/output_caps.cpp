#include "kinds/output_caps.hpp"

#include <string>

#include "base/scene_config.hpp"

namespace conform::scenes {

void check_output_caps(const CommonSettings& c) {
  const long long steps = c.steps;
  // With outputs.vtk every frame is written twice: a PLY file and a .vtu file.
  const long long per_frame = c.vtk ? 2 : 1;
  const long long frames = (c.frames_every > 0 ? steps / c.frames_every + 2 : 2) * per_frame;
  if (frames > kMaxFrames)
    throw SceneError("outputs.frames_every", std::to_string(c.frames_every),
                     "with " + std::to_string(steps) + " steps gives " + std::to_string(frames) +
                         (c.vtk ? " frame files (PLY and .vtu)" : " frames") +
                         ", more than the limit of " + std::to_string(kMaxFrames) +
                         " (a larger outputs.frames_every, or 0 for the first and last only)");
  const long long rows = steps / c.metrics_every + 1;
  if (rows > kMaxMetricRows)
    throw SceneError("outputs.metrics_every", std::to_string(c.metrics_every),
                     "with " + std::to_string(steps) + " steps gives " + std::to_string(rows) +
                         " rows of metrics.csv, more than the limit of " +
                         std::to_string(kMaxMetricRows));
}

}  // namespace conform::scenes
