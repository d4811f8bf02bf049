// Places held by the skin rather than by one bone: a point of a face crossed along its normal
// (a blade on the skin), and a limb's cross-section (its centre, axis and outward side) from
// the vertices either side of it. Evaluated on the skin's positions at the moment of an edit
// (the body's, or the geometric copy's own), they follow whatever the rig, the blend of bones
// and the physics did to that skin.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"

namespace conform::scenes {

/// A point of a face (its corners' barycentric weights) crossed along the face's normal,
/// `reach` either side (bind-pose units, scaled with the face).
struct SkinAnchor {
  std::array<std::int32_t, 3> corners{};
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
  double reach = 0;
  double bind_area = 0;  // the face's area in the bind pose
  /// The blade's two ends at positions `x(v)`: the point ± the reach (scaled as the face's
  /// size) along the face's unit normal (by its corners' order).
  template <class Positions>
  std::pair<Eigen::Vector3d, Eigen::Vector3d> blade(const Positions& x) const;
  /// On the body's positions now.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> blade(const bullet::SkinnedSoftBody& body) const;
};

template <class Positions>
std::pair<Eigen::Vector3d, Eigen::Vector3d> SkinAnchor::blade(const Positions& x) const {
  const Eigen::Vector3d a = x(corners[0]), b = x(corners[1]), c = x(corners[2]);
  const Eigen::Vector3d p = weights(0) * a + weights(1) * b + weights(2) * c;
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double r = reach * std::sqrt(0.5 * n.norm() / bind_area);
  return {p + r * n.normalized(), p - r * n.normalized()};
}

/// A cross-section now.
struct Section {
  Eigen::Vector3d centre, axis, side;  // axis: from the near ring to the far one; side ⟂ axis
  double size = 0;                     // the rings' RMS distance from the centre
  double scale = 1;                    // the size now over the size in the bind pose
};

/// A limb's cross-section held by two rings of its vertices, one either side, and an anchor on
/// its outward side.
struct SkinSection {
  std::vector<std::int32_t> near_ring, far_ring;  // toward the limb's root, and away from it
  SkinAnchor outer;  // on the outward side (a sheet: on the sheet, whose normal is the side)
  bool flat = false;
  double bind_size = 0;  // the rings' RMS distance from the section's centre in the bind pose
  /// At positions `x(v)`: the bind pose's (for planning) or the body's now.
  template <class Positions>
  Section at(const Positions& x) const;
  Section now(const bullet::SkinnedSoftBody& body) const;  // on the body's positions
};

template <class Positions>
Section SkinSection::at(const Positions& x) const {
  const auto mean = [&](const std::vector<std::int32_t>& ring) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const std::int32_t v : ring) c += x(v);
    return Eigen::Vector3d(c / double(ring.size()));
  };
  const Eigen::Vector3d a = mean(near_ring), b = mean(far_ring);
  Section s;
  s.centre = 0.5 * (a + b);
  s.axis = (b - a).normalized();
  const auto& f = outer.corners;
  const Eigen::Vector3d o =
      outer.weights(0) * x(f[0]) + outer.weights(1) * x(f[1]) + outer.weights(2) * x(f[2]);
  const Eigen::Vector3d out = flat ? Eigen::Vector3d((x(f[1]) - x(f[0])).cross(x(f[2]) - x(f[0])))
                                   : Eigen::Vector3d(o - s.centre);
  s.side = (out - out.dot(s.axis) * s.axis).normalized();
  double size2 = 0;
  for (const auto* ring : {&near_ring, &far_ring})
    for (const std::int32_t v : *ring) size2 += (x(v) - s.centre).squaredNorm();
  s.size = std::sqrt(size2 / double(near_ring.size() + far_ring.size()));
  s.scale = bind_size > 0 ? s.size / bind_size : 1.0;
  return s;
}

}  // namespace conform::scenes
