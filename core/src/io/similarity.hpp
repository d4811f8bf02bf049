// Affine 4×4 matrices of a model file as versors. A versor is a proper similarity (dilation,
// rotation, translation); a file's matrices are affine: they may mirror (negative
// determinant) or stretch non-uniformly. The importer makes every product it skins with a
// proper similarity where the file allows it (see import.hpp): mirrors are carried as the
// parity of a node's global transform and conjugated out with the fixed reflection
// F = diag(1, 1, −1), and the rest of the non-similar part is baked into the rest positions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "conform/skin/skeleton.hpp"

namespace conform::io::detail {

/// A matrix as the nearest proper similarity: rotation the polar factor, scale the mean
/// singular value. `exact` when the matrix was one (singular values equal to 1e-5 relative,
/// positive determinant).
struct NearestVersor {
  skin::Versor versor;
  bool exact = true;
  bool mirror = false;  // negative determinant: the reflection was dropped
};

/// Empty for a NaN, singular or projective matrix.
std::optional<NearestVersor> nearest_versor(const Eigen::Matrix4d& m);

/// True when `m` is a proper similarity to the tolerance of nearest_versor.
bool is_proper_similarity(const Eigen::Matrix4d& m);

/// F m (when `left`) and m F (when `right`), F = diag(1, 1, −1).
Eigen::Matrix4d reflected(Eigen::Matrix4d m, bool left, bool right);

/// The rotation F R F as a unit quaternion: (w, x, y, z) → (w, −x, −y, z), continuous along a
/// track (no sign flips), so that interpolation commutes with it.
Eigen::Quaterniond reflected(const Eigen::Quaterniond& q);

}  // namespace conform::io::detail
