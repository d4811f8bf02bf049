// Where the character scene's edits land on a user's model, in its bind pose. By default an
// edit is aimed at a limb: a bone and every bone below it, the largest connected piece of the
// vertices they dominate, with the limb's principal axis (pointing away from its root joint), its
// extent along it and its radius about it. The cut is the limb's cross-section at a fraction
// `along` of its length; the tear's blade runs along the limb's outer side (or inner side), snapped
// to the nearest point of the limb's skin sample by sample and crossing it along the skin's normal;
// the drill goes through the limb across its axis (through a flat part along its normal). Without a
// named bone the limb is the one where a trial on the skinned model lands the edits best (the
// whole model is the last candidate). Given `cut.point`, `tear.from` or `drill.tip`, an edit is
// placed in the bind pose's bounding box as before.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/skin/animation.hpp"
#include "conform/skin/skeleton.hpp"
#include "kinds/character_edits.hpp"

namespace conform::scenes {

/// A limb of the model in its bind pose.
struct Limb {
  std::int32_t bone = -1;              // its root bone (−1: the whole model)
  std::vector<std::int32_t> vertices;  // dominated by the root bone or a bone below it
  std::vector<std::int32_t> faces;     // with a vertex among them
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // principal, away from the root joint
  Eigen::Vector3d side = Eigen::Vector3d::UnitY();  // outward: away from the model's centre
  double from = 0, to = 0;  // its vertices' extent along the axis, about the centre
  double radius = 0;        // median distance of its vertices from the axis
  bool flat = false;        // a sheet, not a tube: `side` is its normal
  /// The axis point at `along` (0 at the root end, 1 at the far end).
  Eigen::Vector3d at(double along) const { return centre + (from + along * (to - from)) * axis; }
  double length() const { return to - from; }
};

/// The limb rooted at `bone` (an index of `skeleton.bones`); throws naming `key` when its
/// bones dominate fewer than 4 vertices.
Limb limb_of(const BindPose& bind, const skin::Skeleton& skeleton, std::int32_t bone,
             const std::string& key);
/// The bone named `name` (−1 when empty); throws naming `key` when there is none.
std::int32_t named_bone(const skin::Skeleton& skeleton, const std::string& name,
                        const std::string& key);
/// The root bone's name, or "(the whole model)" for −1.
std::string limb_name(const skin::Skeleton& skeleton, std::int32_t bone);
/// Bones whose limbs are limbs (between 1 % and 60 % of the vertices, at least 8): those
/// without an open border first, then the elongated ones, then the thickest.
std::vector<std::int32_t> limb_candidates(const BindPose& bind, const skin::Skeleton& skeleton);
/// The limb edits aim at by default, tried on `mesh` skinned as `animation` (none: the bind
/// pose) has it at the edits' times, without physics: the candidate whose section at
/// `cut.along` closes as one capped loop, whose tear (`tear`'s stroke on the limb) extends at
/// the most samples and whose drill lands (with its tube), the first of equals. The whole
/// model (−1) is the last candidate.
std::int32_t auto_aim(const mesh::SkinnedMesh& mesh, const BindPose& bind,
                      const skin::Skeleton& skeleton, const skin::Animation* animation,
                      const CutEdit& cut, const TearEdit& tear, const DrillEdit& drill);

/// Each edit in the bind pose: on the limb its `bone` names, else on `aim`'s, or in the box.
PlacedCut place_cut(const CutEdit& edit, const BindPose& bind, const skin::Skeleton& skeleton,
                    std::int32_t aim);
PlacedTear place_tear(const TearEdit& edit, const BindPose& bind, const skin::Skeleton& skeleton,
                      std::int32_t aim);
PlacedDrill place_drill(const DrillEdit& edit, const BindPose& bind, const skin::Skeleton& skeleton,
                        std::int32_t aim);

}  // namespace conform::scenes
