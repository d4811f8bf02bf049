#include "kinds/surface_point.hpp"

#include <algorithm>
#include <limits>

namespace conform::scenes {

using Vec3 = Eigen::Vector3d;

namespace {

// The point of triangle abc nearest p: p's projection onto the plane when it falls inside,
// else the nearest point of the nearest edge (each edge's clamped segment projection).
Vec3 nearest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const Vec3 q = p - n * (n.dot(p - a) / n.squaredNorm());
  // Inside when q lies on the inner side of every edge.
  if (n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 &&
      n.dot((a - c).cross(q - c)) >= 0)
    return q;
  const auto on_segment = [&](const Vec3& u, const Vec3& v) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return Vec3(u + t * (v - u));
  };
  Vec3 best = on_segment(a, b);
  for (const Vec3& r : {on_segment(b, c), on_segment(c, a)})
    if ((r - p).squaredNorm() < (best - p).squaredNorm()) best = r;
  return best;
}

}  // namespace

SurfacePoint nearest_surface_point(const Eigen::Matrix3Xd& x, std::span<const mesh::Face> all,
                                   std::span<const std::int32_t> faces, const Vec3& query) {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const std::int32_t f : faces) {
    const mesh::Face& t = all[static_cast<std::size_t>(f)];
    const Vec3 a = x.col(t[0]), b = x.col(t[1]), c = x.col(t[2]);
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.squaredNorm() > 0)) continue;
    const Vec3 q = nearest_on_triangle(query, a, b, c);
    const double d = (q - query).norm();
    if (d >= best.distance) continue;
    best = {q, n.normalized(), f, d};
    if (best.normal.dot(query - q) < 0) best.normal = -best.normal;
  }
  if (best.face < 0) best.distance = 0;
  return best;
}

}  // namespace conform::scenes
