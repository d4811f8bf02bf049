#include "kinds/skin_frame.hpp"

#include <cmath>

namespace conform::scenes {

using Vec3 = Eigen::Vector3d;

std::pair<Vec3, Vec3> SkinAnchor::blade(const bullet::SkinnedSoftBody& body) const {
  return blade([&](std::int32_t v) { return body.position(v); });
}

Section SkinSection::now(const bullet::SkinnedSoftBody& body) const {
  return at([&](std::int32_t v) { return body.position(v); });
}

}  // namespace conform::scenes
