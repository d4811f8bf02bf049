#include "cli/model_pose.hpp"

#include <cmath>
#include <stdexcept>

#include "conform/skin/skinner.hpp"

namespace conform::cli {

const skin::Animation& find_animation_or_throw(const io::SkinnedModel& model,
                                               const std::string& key) {
  const int i = model.find_animation(key);
  if (i < 0)
    throw std::invalid_argument(model.source + ": no animation named or numbered '" + key + "' (" +
                                std::to_string(model.animations.size()) + " animations)");
  return model.animations[static_cast<std::size_t>(i)];
}

void pose_model(io::SkinnedModel& model, const std::string& key, double seconds) {
  if (!std::isfinite(seconds) || seconds < 0)
    throw std::invalid_argument("--time = " + std::to_string(seconds) +
                                " is out of range (finite, >= 0 s)");
  const skin::Animation& animation = find_animation_or_throw(model, key);
  skin::Pose pose = skin::Pose::rest(model.skeleton);
  animation.sample(model.skeleton, seconds, skin::Blend::log, pose);
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences);
  skinner.skin(pose, skin::SkinMode::cga);
  skinner.write(model.mesh.current);
}

}  // namespace conform::cli
