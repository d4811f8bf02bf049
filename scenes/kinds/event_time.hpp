// When a scene's events (a cut, a drill, a slit, a tear's samples, a flex of the pose) happen:
// between steps, at the first step whose time reaches the event's. An event after the last
// step would never happen; every scene refuses it alike, before its run starts.
#pragma once

#include <string>

#include "kinds/run_output.hpp"

namespace conform::scenes {

/// Step times are multiples of dt, event times decimals: an event is due this much early.
inline constexpr double kEventSlack = 1e-12;

/// True when an event at `at` seconds is due at the step that ends at `t`.
inline bool event_due(double t, double at) {
  return t >= at - kEventSlack;
}

/// Throws SceneError for an event that happens at `time` seconds, after the run's last step
/// (c.steps × c.dt): naming `key` and its `value`, the event (`what`, e.g. "the cut") and the
/// scene's duration. The message says "is after the last step".
void require_before_end(const CommonSettings& c, const std::string& key, double value,
                        const std::string& what, double time);

}  // namespace conform::scenes
