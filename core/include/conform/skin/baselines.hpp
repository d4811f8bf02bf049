// Baselines for tests and benchmarks: matrix linear blend skinning (Eigen 4×4 matrices, the
// classical pipeline of the second paper's §3) and dual-quaternion skinning (Kavan et al.,
// with a blended uniform scale applied first, as the versor blend does).
//
// Same SoA layout and job shape as skinning.hpp.
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "conform/skin/pose.hpp"
#include "conform/skin/skinning.hpp"

namespace conform::skin {

/// Bone matrices the classical way: each joint's local matrix T · R · S from the pose's
/// translation, rotation (Eigen quaternion → matrix) and scale, the hierarchy walk as 4×4
/// products G_j = G_parent L_j, and the skinning matrix G_j O_n. Buffers are allocated once.
class MatrixRig {
 public:
  explicit MatrixRig(const Skeleton& skeleton);
  /// Recomputes the skinning matrices for `pose` (no allocation).
  void update(const Pose& pose);
  std::span<const Eigen::Matrix4d> skinning_matrices() const { return skin_; }
  /// The top 3 rows of each skinning matrix, row-major.
  template <class T>
  void kernels(std::span<Kernel34<T>> out) const;

 private:
  const Skeleton* skeleton_;
  std::vector<Eigen::Matrix4d> offsets_, global_, skin_;
};

/// 4×4 matrix T · R · S of a versor's translation, rotation and (uniform) scale.
Eigen::Matrix4d trs_matrix(const Versor& v);

/// Matrix LBS: per vertex, blend the bone matrices M = Σ w_n M_n, then x' = M x.
template <class T>
struct LbsSkinningJob {
  std::span<const Kernel34<T>> matrices;
  SkinInput<T> input;
  SkinOutput<T> output;
  int threads = 0;

  std::string validate() const { return validate_skin_io(input, output, matrices.size()); }
  void run() const;
};

/// A bone for dual-quaternion skinning: unit rotation q, dual part ½ t q, uniform scale.
template <class T>
struct DqBone {
  T qw, qx, qy, qz;  // real part
  T dw, dx, dy, dz;  // dual part
  T scale;
};

/// From similarity matrices s R | t (scale s = det^(1/3)).
template <class T>
void dq_bones(std::span<const Eigen::Matrix4d> matrices, std::span<DqBone<T>> out);

/// Dual-quaternion skinning: blend Σ ±w_n (q_n + ε d_n) (signs aligned with the first
/// influence), normalize by |q|, scale d = Σ w_n s_n, and x' = q (d x) q* + 2 d q* (vector).
template <class T>
struct DqSkinningJob {
  std::span<const DqBone<T>> bones;
  SkinInput<T> input;
  SkinOutput<T> output;
  int threads = 0;

  std::string validate() const { return validate_skin_io(input, output, bones.size()); }
  void run() const;
};

}  // namespace conform::skin
