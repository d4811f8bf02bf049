#include "conform/skin/animation.hpp"

#include <algorithm>
#include <cmath>

namespace conform::skin {
namespace {

using Motor = cga::Motor<double>;

// The two keys around `t` and the blend factor between them; clamped at the ends.
template <class V>
void bracket(const std::vector<Key<V>>& keys, double t, std::size_t& i0, std::size_t& i1,
             double& alpha) {
  if (t <= keys.front().time) {
    i0 = i1 = 0, alpha = 0;
    return;
  }
  if (t >= keys.back().time) {
    i0 = i1 = keys.size() - 1, alpha = 0;
    return;
  }
  const auto hi = std::upper_bound(keys.begin(), keys.end(), t,
                                   [](double x, const Key<V>& k) { return x < k.time; });
  i1 = static_cast<std::size_t>(hi - keys.begin());
  i0 = i1 - 1;
  const double span = keys[i1].time - keys[i0].time;
  alpha = span > 0 ? (t - keys[i0].time) / span : 0;
}

template <class V>
std::string check_times(const std::vector<Key<V>>& keys, const char* kind) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!std::isfinite(keys[i].time))
      return std::string("non-finite ") + kind + " key time at key " + std::to_string(i);
    if (i > 0 && keys[i].time < keys[i - 1].time)
      return std::string(kind) + " key times are not sorted at key " + std::to_string(i);
  }
  return {};
}

}  // namespace

std::vector<double> Animation::key_times() const {
  std::vector<double> t;
  for (const auto& c : channels) {
    for (const auto& k : c.translation) t.push_back(k.time / ticks_per_second);
    for (const auto& k : c.rotation) t.push_back(k.time / ticks_per_second);
    for (const auto& k : c.scale) t.push_back(k.time / ticks_per_second);
  }
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

std::string Animation::validate(const Skeleton& skeleton) const {
  const std::string where = "animation '" + name + "': ";
  if (!(ticks_per_second > 0) || !std::isfinite(ticks_per_second))
    return where + "ticks per second must be positive";
  if (!std::isfinite(duration_ticks) || duration_ticks < 0)
    return where + "duration must be finite and non-negative";
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const auto& ch = channels[c];
    const std::string cw = where + "channel " + std::to_string(c) + ": ";
    if (ch.joint < 0 || ch.joint >= skeleton.joint_count())
      return cw + "joint " + std::to_string(ch.joint) + " out of range";
    for (const auto& e : {check_times(ch.translation, "translation"),
                          check_times(ch.rotation, "rotation"), check_times(ch.scale, "scale")})
      if (!e.empty()) return cw + e;
    for (std::size_t i = 0; i < ch.translation.size(); ++i)
      if (!ch.translation[i].value.allFinite())
        return cw + "NaN or infinite translation key " + std::to_string(i);
    for (std::size_t i = 0; i < ch.rotation.size(); ++i) {
      const auto& q = ch.rotation[i].value;
      if (!q.coeffs().allFinite()) return cw + "NaN or infinite rotation key " + std::to_string(i);
      if (!(q.squaredNorm() > 1e-12))
        return cw + "zero rotation quaternion at key " + std::to_string(i);
    }
    for (std::size_t i = 0; i < ch.scale.size(); ++i)
      if (!std::isfinite(ch.scale[i].value) || !(ch.scale[i].value > 0))
        return cw + "NaN, infinite or non-positive scale key " + std::to_string(i);
  }
  return {};
}

Versor sample_channel(const Channel& ch, const Versor& rest, double t, Blend mode) {
  std::size_t i0, i1;
  double a;
  // Translation: blend of the translators T_i = 1 − ½ t_i e∞.
  Eigen::Vector3d trans = rest.motor.translation();
  if (!ch.translation.empty()) {
    bracket(ch.translation, t, i0, i1, a);
    const Motor m0 = Motor::from_translation(ch.translation[i0].value);
    if (i0 == i1) {
      trans = ch.translation[i0].value;
    } else {
      const Motor m1 = Motor::from_translation(ch.translation[i1].value);
      trans = (mode == Blend::log ? cga::blend_log(m0, m1, a) : cga::blend_linear(m0, m1, a))
                  .translation();
    }
  }
  // Rotation: blend of the rotors (normalized lerp, or slerp for the log blend).
  Eigen::Quaterniond rot = rest.motor.rotation().normalized();
  if (!ch.rotation.empty()) {
    bracket(ch.rotation, t, i0, i1, a);
    if (i0 == i1) {
      rot = ch.rotation[i0].value.normalized();
    } else {
      const Motor r0 = Motor::from_quaternion(ch.rotation[i0].value.normalized());
      const Motor r1 = Motor::from_quaternion(ch.rotation[i1].value.normalized());
      rot = (mode == Blend::log ? cga::blend_log(r0, r1, a) : cga::blend_linear(r0, r1, a))
                .rotation()
                .normalized();
    }
  }
  // Scale: blend of the dilators (linear, or geometric for the log blend).
  double scale = rest.scale;
  if (!ch.scale.empty()) {
    bracket(ch.scale, t, i0, i1, a);
    const double s0 = ch.scale[i0].value, s1 = ch.scale[i1].value;
    scale = i0 == i1             ? s0
            : mode == Blend::log ? std::exp((1 - a) * std::log(s0) + a * std::log(s1))
                                 : (1 - a) * s0 + a * s1;
  }
  // T R D: dilate, rotate, translate.
  return Versor::from_trs(trans, rot, scale);
}

void Animation::sample(const Skeleton& skeleton, double seconds, Blend mode, Pose& out) const {
  out.local.resize(skeleton.joints.size());
  for (std::size_t i = 0; i < skeleton.joints.size(); ++i) out.local[i] = skeleton.joints[i].rest;
  const double ticks = seconds * ticks_per_second;  // each track holds its end keys outside
  for (const auto& ch : channels) {
    const auto j = static_cast<std::size_t>(ch.joint);
    out.local[j] = sample_channel(ch, skeleton.joints[j].rest, ticks, mode);
  }
}

}  // namespace conform::skin
