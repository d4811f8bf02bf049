#include "track_vertex.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace conform::mesh {

namespace {

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double u = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + u * ab - p).norm();
}

double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0 && n.dot((b - a).cross(p - a)) >= 0 && n.dot((c - b).cross(p - b)) >= 0 &&
      n.dot((a - c).cross(p - c)) >= 0)
    return std::abs(n.dot(p - a)) / std::sqrt(n2);
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

// Distance to the blade's swept quad (previous blade, current blade), as the lips test measures
// the border, and to the quad that the next step will likely sweep (the step repeated): a vertex
// just ahead of the hit lies on the track that the next sample covers.
double track_distance(const Eigen::Vector3d& p, const std::array<Eigen::Vector3d, 4>& s) {
  const Eigen::Vector3d na = 2 * s[2] - s[0], nb = 2 * s[3] - s[1];
  return std::min({triangle_distance(p, s[0], s[1], s[3]), triangle_distance(p, s[0], s[3], s[2]),
                   triangle_distance(p, s[2], s[3], nb), triangle_distance(p, s[2], nb, na)});
}

}  // namespace

std::int32_t track_vertex(const SkinnedMesh& mesh, const std::vector<std::int32_t>& candidates,
                          const TrackVertexQuery& q) {
  const Eigen::Vector3d step = q.hit - q.previous;
  const double length = step.norm();
  if (!(length > 0) || !(q.edge > 0)) return -1;
  const Eigen::Vector3d dir = step / length;
  std::int32_t best = -1;
  double nearest = 0;
  for (const std::int32_t v : candidates) {
    const Eigen::Vector3d p = mesh.current.col(v);
    // Along the track: the steps before and after the tip stay near one step each.
    const double x = (p - q.hit).dot(dir);
    if (x < -q.behind * length || x > q.ahead * length) continue;
    const double d = track_distance(p, q.sweep);
    if (d > q.across * q.edge) continue;
    const double r = (p - q.hit).norm();
    if (best < 0 || r < nearest) best = v, nearest = r;
  }
  return best;
}

}  // namespace conform::mesh
