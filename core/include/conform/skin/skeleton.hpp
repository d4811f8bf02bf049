// The skeleton of a skinned model: a joint hierarchy (every node that a bone or an animated
// node depends on) and the bones, i.e. the joints that deform vertices, with their bind
// (offset) versors B_n of the second paper's eq 17.
//
// Every transform is a versor V = M D (dilation about the origin, then the rigid motion M),
// so x' = d R x + t (see conform/cga/versor.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "conform/cga/versor.hpp"

namespace conform::skin {

using Versor = cga::Versor<double>;

struct Joint {
  std::string name;
  std::int32_t parent = -1;  // index of the parent joint (< this joint's index), −1 for a root
  Versor rest;               // the node's own transform, relative to its parent
};

struct Bone {
  std::string name;
  std::int32_t joint = 0;  // the joint whose global versor moves this bone
  Versor offset;           // B_n: mesh space → the joint's space in the bind pose
};

struct Skeleton {
  std::vector<Joint> joints;  // topologically sorted: parents before children
  std::vector<Bone> bones;    // SkinnedMesh::bones index this array

  std::int32_t joint_count() const { return static_cast<std::int32_t>(joints.size()); }
  std::int32_t bone_count() const { return static_cast<std::int32_t>(bones.size()); }
  /// Index of the joint named `name`, or −1.
  std::int32_t find_joint(std::string_view name) const {
    for (std::size_t i = 0; i < joints.size(); ++i)
      if (joints[i].name == name) return static_cast<std::int32_t>(i);
    return -1;
  }
  /// Index of the bone named `name`, or −1.
  std::int32_t find_bone(std::string_view name) const {
    for (std::size_t i = 0; i < bones.size(); ++i)
      if (bones[i].name == name) return static_cast<std::int32_t>(i);
    return -1;
  }
  /// Empty when well formed, else a description of the first problem (parent order, bone
  /// joint out of range, non-positive or non-finite scale).
  std::string validate() const;
};

}  // namespace conform::skin
