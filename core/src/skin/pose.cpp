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

namespace {

// (M_a D_a)(M_b D_b) = M_a (D_a M_b D_a⁻¹) D_a D_b (versor.hpp). Conjugating by a dilation
// scales the translation, and a motor's e∞ part −½ t R (e1∞, e2∞, e3∞, e123∞) is linear in t,
// so D_a M_b D_a⁻¹ is M_b with those four components times d_a: no need to extract and rebuild
// the translation as Versor::operator* does.
Versor compose(const Versor& a, const Versor& b) {
  cga::Motor<double> m = b.motor;
  m.e1inf *= a.scale, m.e2inf *= a.scale, m.e3inf *= a.scale, m.e123inf *= a.scale;
  return {a.motor * m, a.scale * b.scale};
}

}  // namespace

void global_versors(const Skeleton& skeleton, const Pose& pose, std::span<Versor> global) {
  const std::size_t n = skeleton.joints.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto parent = skeleton.joints[i].parent;
    global[i] = parent < 0 ? pose.local[i]
                           : compose(global[static_cast<std::size_t>(parent)], pose.local[i]);
  }
}

void skinning_versors(const Skeleton& skeleton, std::span<const Versor> global,
                      std::span<Versor> out) {
  for (std::size_t n = 0; n < skeleton.bones.size(); ++n) {
    const auto& b = skeleton.bones[n];
    out[n] = compose(global[static_cast<std::size_t>(b.joint)], b.offset);
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
