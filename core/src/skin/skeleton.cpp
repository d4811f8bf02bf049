#include "conform/skin/skeleton.hpp"

#include <cmath>

namespace conform::skin {
namespace {

bool finite_versor(const Versor& v) {
  const auto& m = v.motor;
  return std::isfinite(m.s) && std::isfinite(m.e12) && std::isfinite(m.e13) &&
         std::isfinite(m.e23) && std::isfinite(m.e1inf) && std::isfinite(m.e2inf) &&
         std::isfinite(m.e3inf) && std::isfinite(m.e123inf) && std::isfinite(v.scale) &&
         v.scale > 0 && m.rotation_norm_squared() > 0;
}

}  // namespace

std::string Skeleton::validate() const {
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto& j = joints[i];
    if (j.parent < -1 || j.parent >= static_cast<std::int32_t>(i))
      return "joint " + std::to_string(i) + " ('" + j.name + "') has parent " +
             std::to_string(j.parent) + ", which does not come before it";
    if (!finite_versor(j.rest))
      return "joint " + std::to_string(i) + " ('" + j.name +
             "') has a non-finite or singular "
             "transform";
  }
  for (std::size_t i = 0; i < bones.size(); ++i) {
    const auto& b = bones[i];
    if (b.joint < 0 || b.joint >= joint_count())
      return "bone " + std::to_string(i) + " ('" + b.name + "') refers to joint " +
             std::to_string(b.joint) + " of " + std::to_string(joints.size());
    if (!finite_versor(b.offset))
      return "bone " + std::to_string(i) + " ('" + b.name +
             "') has a non-finite or singular "
             "offset";
  }
  return {};
}

}  // namespace conform::skin
