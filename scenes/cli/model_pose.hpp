// Choosing an animation of a model by name or index, and posing the model at a time: what the
// commands that take --animation and --time share.
#pragma once

#include <string>

#include "conform/io/model.hpp"

namespace conform::cli {

/// The animation named `key`, or numbered `key`. Throws std::invalid_argument naming the model,
/// the key and how many animations there are.
const skin::Animation& find_animation_or_throw(const io::SkinnedModel& model,
                                               const std::string& key);

/// Skins `model.mesh.current` (CGA, log blend) at `seconds` of the animation `key`. Throws
/// std::invalid_argument for an unknown animation or a non-finite or negative time.
void pose_model(io::SkinnedModel& model, const std::string& key, double seconds);

}  // namespace conform::cli
