// Bounded outputs: how many frames and rows a command may write, checked before anything is
// written (`skin --frames 2147483647` wrote until the disk was full).
#pragma once

#include <cstdint>

#include "kinds/run_output.hpp"

namespace conform::scenes {

/// Mesh files one command writes: `skin --frames`, and a scene run's frames (steps /
/// outputs.frames_every, plus the first and the last; twice that with outputs.vtk).
inline constexpr long long kMaxFrames = 10000;
/// Rows of a scene run's metrics.csv (steps / outputs.metrics_every).
inline constexpr long long kMaxMetricRows = 1000000;
/// What `skin` may write in all, MiB, unless --max-output-mib says otherwise.
inline constexpr double kDefaultMaxOutputMib = 4096;

/// Throws SceneError naming outputs.frames_every or outputs.metrics_every when the run would
/// write more frames or metric rows than the caps above.
void check_output_caps(const CommonSettings& c);

}  // namespace conform::scenes
