// Poses: one local versor per joint, the hierarchy walk to global versors, the skinning
// versors M_n,k B_n of eq 17, and keyframes made on the fly (set a joint's local rotation,
// translation and dilation; blend poses).
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "conform/skin/skeleton.hpp"

namespace conform::skin {

/// How two versors are interpolated (second paper §2.5): `linear` is the normalized
/// (1 − α) m1 + α m2, `log` is m1 exp(α log(m1⁻¹ m2)) (slerp for rotations, screw motion for
/// rigid motions, geometric for scales).
enum class Blend { linear, log };

/// Parses "linear" / "log"; false on anything else.
bool parse_blend(std::string_view text, Blend& out);

inline Versor blend(const Versor& a, const Versor& b, double alpha, Blend mode) {
  return mode == Blend::log ? cga::blend_log(a, b, alpha) : cga::blend_linear(a, b, alpha);
}

/// Local versor of every joint, relative to its parent.
struct Pose {
  std::vector<Versor> local;

  /// The skeleton's rest (bind-time node) pose.
  static Pose rest(const Skeleton& skeleton);

  /// Sets joint `joint`'s local transform to: dilate by `dilation` about the joint, rotate by
  /// `rotation`, then translate by `translation` (relative to the parent joint).
  void set_local(std::int32_t joint, const Eigen::Quaterniond& rotation,
                 const Eigen::Vector3d& translation, double dilation = 1.0) {
    local.at(static_cast<std::size_t>(joint)) =
        Versor::from_trs(translation, rotation.normalized(), dilation);
  }
  /// Post-multiplies a joint's local transform by `delta` (a change in the joint's own frame,
  /// e.g. a rotation or a dilation about the joint).
  void apply_local(std::int32_t joint, const Versor& delta) {
    auto& v = local.at(static_cast<std::size_t>(joint));
    v = v * delta;
  }
};

/// Per-joint blend of two poses of the same skeleton. Requires a.local.size() == b.local.size().
void blend(const Pose& a, const Pose& b, double alpha, Blend mode, Pose& out);

/// Global versors: G_j = G_parent(j) · L_j, walking the (topologically sorted) hierarchy.
/// `global` must have skeleton.joint_count() entries.
void global_versors(const Skeleton& skeleton, const Pose& pose, std::span<Versor> global);

/// Skinning versors M_n,k B_n of eq 17: the global versor of bone n's joint times its offset.
/// `out` must have skeleton.bone_count() entries.
void skinning_versors(const Skeleton& skeleton, std::span<const Versor> global,
                      std::span<Versor> out);

/// Keyframes made on the fly: poses at times (seconds), sampled by blending the two
/// neighbouring keys (clamped outside the range). Linear blending is the paper's choice for
/// user-made keyframes.
class PoseTrack {
 public:
  /// Adds (or replaces) the key at `time`; keys stay sorted.
  void set_key(double time, Pose pose);
  std::size_t size() const { return keys_.size(); }
  const std::vector<std::pair<double, Pose>>& keys() const { return keys_; }
  /// Empty track: leaves `out` unchanged and returns false.
  bool sample(double time, Blend mode, Pose& out) const;

 private:
  std::vector<std::pair<double, Pose>> keys_;
};

}  // namespace conform::skin
