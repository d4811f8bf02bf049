#include "conform/skin/pose.hpp"

#include <algorithm>

namespace conform::skin {

bool parse_blend(std::string_view text, Blend& out) {
  if (text == "linear") {
    out = Blend::linear;
    return true;
  }
  if (text == "log") {
    out = Blend::log;
    return true;
  }
  return false;
}

Pose Pose::rest(const Skeleton& skeleton) {
  Pose p;
  p.local.reserve(skeleton.joints.size());
  for (const auto& j : skeleton.joints) p.local.push_back(j.rest);
  return p;
}

void blend(const Pose& a, const Pose& b, double alpha, Blend mode, Pose& out) {
  out.local.resize(a.local.size());
  for (std::size_t i = 0; i < a.local.size(); ++i)
    out.local[i] = blend(a.local[i], b.local[i], alpha, mode);
}

void global_versors(const Skeleton& skeleton, const Pose& pose, std::span<Versor> global) {
  const std::size_t n = skeleton.joints.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto parent = skeleton.joints[i].parent;
    global[i] =
        parent < 0 ? pose.local[i] : global[static_cast<std::size_t>(parent)] * pose.local[i];
  }
}

void skinning_versors(const Skeleton& skeleton, std::span<const Versor> global,
                      std::span<Versor> out) {
  for (std::size_t n = 0; n < skeleton.bones.size(); ++n) {
    const auto& b = skeleton.bones[n];
    out[n] = global[static_cast<std::size_t>(b.joint)] * b.offset;
  }
}

void PoseTrack::set_key(double time, Pose pose) {
  auto it = std::lower_bound(keys_.begin(), keys_.end(), time,
                             [](const auto& k, double t) { return k.first < t; });
  if (it != keys_.end() && it->first == time)
    it->second = std::move(pose);
  else
    keys_.insert(it, {time, std::move(pose)});
}

bool PoseTrack::sample(double time, Blend mode, Pose& out) const {
  if (keys_.empty()) return false;
  if (time <= keys_.front().first) {
    out = keys_.front().second;
    return true;
  }
  if (time >= keys_.back().first) {
    out = keys_.back().second;
    return true;
  }
  const auto hi = std::upper_bound(keys_.begin(), keys_.end(), time,
                                   [](double t, const auto& k) { return t < k.first; });
  const auto lo = hi - 1;
  const double alpha = (time - lo->first) / (hi->first - lo->first);
  blend(lo->second, hi->second, alpha, mode, out);
  return true;
}

}  // namespace conform::skin
