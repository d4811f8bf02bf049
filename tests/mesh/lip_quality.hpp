// How much a tear's border looks like a wound, measured on the mesh alone:
// how far the border lies from the blade's swept surface, how evenly its points are spaced,
// how many thin triangles converge on one vertex, and, after opening, how sharply each lip
// turns from one segment to the next.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/tear.hpp"

namespace conform::test {

struct LipQuality {
  double track_distance = 0;  // largest border-vertex distance to the swept surface / local edge
  double spacing_ratio = 0;   // longest / shortest interior border segment
  int fan = 0;                // most thin added faces (smallest angle < kThinDeg) at one vertex
  double turning_deg = 0;     // largest lip turning angle after opening, ends excluded
};

inline constexpr double kThinDeg = 15;

inline double point_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double u = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + u * ab - p).norm();
}

// Distance from p to triangle (a, b, c).
inline double point_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0 && n.dot((b - a).cross(p - a)) >= 0 && n.dot((c - b).cross(p - b)) >= 0 &&
      n.dot((a - c).cross(p - c)) >= 0)
    return std::abs(n.dot(p - a)) / std::sqrt(n2);
  return std::min({point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a)});
}

// The mean edge length of the input face nearest p: the local edge length there.
inline double local_edge(const mesh::SkinnedMesh& in, const Eigen::Vector3d& p) {
  double best = 1e300, edge = 0;
  for (const mesh::Face& f : in.faces) {
    const Eigen::Vector3d a = in.current.col(f[0]), b = in.current.col(f[1]),
                          c = in.current.col(f[2]);
    const double d = point_triangle(p, a, b, c);
    if (d < best) best = d, edge = ((b - a).norm() + (c - b).norm() + (a - c).norm()) / 3;
  }
  return edge;
}

// The swept surface of the blade: two triangles between each pair of successive samples.
inline double swept_distance(const std::vector<mesh::ScalpelSample>& samples,
                             const Eigen::Vector3d& p) {
  double d = 1e300;
  for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
    const auto &s = samples[i], &t = samples[i + 1];
    d = std::min({d, point_triangle(p, s.a, s.b, t.b), point_triangle(p, s.a, t.b, t.a)});
  }
  return d;
}

// The faces of `out` not in `in` with smallest angle below kThinDeg, counted per vertex.
inline int thin_fan(const mesh::SkinnedMesh& in, const mesh::SkinnedMesh& out) {
  auto key = [](mesh::Face f) {
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    return f;
  };
  std::set<mesh::Face> old;
  for (const mesh::Face& f : in.faces) old.insert(key(f));
  std::map<std::int32_t, int> count;
  int most = 0;
  for (const mesh::Face& f : out.faces) {
    if (old.count(key(f))) continue;
    const double angle =
        mesh::smallest_angle(out.current.col(f[0]), out.current.col(f[1]), out.current.col(f[2]));
    if (angle * 180 / std::acos(-1.0) >= kThinDeg) continue;
    for (const std::int32_t v : f) most = std::max(most, ++count[v]);
  }
  return most;
}

// The largest turning angle (degrees) between consecutive segments of a border chain, at its
// vertices 2 … n − 3 (the ends, where the lips meet, excluded).
inline double turning(const mesh::SkinnedMesh& m, const std::vector<std::int32_t>& border) {
  double worst = 0;
  for (std::size_t i = 2; i + 2 < border.size(); ++i) {
    const Eigen::Vector3d u = m.current.col(border[i]) - m.current.col(border[i - 1]),
                          w = m.current.col(border[i + 1]) - m.current.col(border[i]);
    if (!(u.norm() > 0 && w.norm() > 0)) continue;
    worst = std::max(worst, std::atan2(u.cross(w).norm(), u.dot(w)) * 180 / std::acos(-1.0));
  }
  return worst;
}

// The border measured on the torn mesh (before opening), then the tear opened by `amount`
// (Algorithm 2 step 6) and its lips measured.
inline LipQuality lip_quality(const mesh::SkinnedMesh& in, mesh::SkinnedMesh& m, mesh::Tear& tear,
                              const std::vector<mesh::ScalpelSample>& samples, double amount) {
  LipQuality q;
  const auto right = tear.right_border();
  for (const std::int32_t v : right) {
    const Eigen::Vector3d p = m.current.col(v);
    q.track_distance = std::max(q.track_distance, swept_distance(samples, p) / local_edge(in, p));
  }
  double shortest = 1e300, longest = 0;
  for (std::size_t i = 2; i + 1 < right.size(); ++i) {
    const double l = (m.current.col(right[i]) - m.current.col(right[i - 1])).norm();
    shortest = std::min(shortest, l), longest = std::max(longest, l);
  }
  q.spacing_ratio = longest > 0 ? longest / shortest : 0;
  q.fan = thin_fan(in, m);
  tear.open(amount);
  q.turning_deg = std::max(turning(m, tear.left_border()), turning(m, right));
  return q;
}

}  // namespace conform::test
