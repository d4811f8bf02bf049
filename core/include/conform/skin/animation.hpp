// Keyframed animations: per-joint channels of translation, rotation and (uniform) scale keys,
// sampled at any time by blending each track's neighbouring keys as versors — translators,
// rotors and dilators — and composing the local versor T R D (eq 15 with versors in place of
// matrices). Joints without a channel, and channels without keys of a kind, keep the
// corresponding part of the joint's rest transform.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "conform/skin/pose.hpp"

namespace conform::skin {

template <class V>
struct Key {
  double time = 0;  // ticks
  V value;
};

struct Channel {
  std::int32_t joint = 0;
  std::vector<Key<Eigen::Vector3d>> translation;  // sorted by time
  std::vector<Key<Eigen::Quaterniond>> rotation;  // unit quaternions
  std::vector<Key<double>> scale;                 // uniform scale factors, > 0
};

struct Animation {
  std::string name;
  double duration_ticks = 0;
  double ticks_per_second = 25;  // the importer substitutes 25 when a file says 0
  std::vector<Channel> channels;

  double duration() const { return duration_ticks / ticks_per_second; }
  /// Every key time of every channel, in seconds, sorted and without duplicates.
  std::vector<double> key_times() const;
  /// Empty when well formed, else the first problem: joint out of range, unsorted or
  /// non-finite key times, non-finite values, non-positive scales, zero quaternions,
  /// non-positive ticks per second.
  std::string validate(const Skeleton& skeleton) const;

  /// The pose at `seconds`: rest pose overridden by the channels; before its first key and
  /// after its last, a track holds that key.
  /// `out.local` is resized to the skeleton's joint count (no allocation once sized).
  void sample(const Skeleton& skeleton, double seconds, Blend mode, Pose& out) const;
};

/// The local transform a channel gives at `ticks`, with `rest` supplying missing tracks.
Versor sample_channel(const Channel& channel, const Versor& rest, double ticks, Blend mode);

}  // namespace conform::skin
