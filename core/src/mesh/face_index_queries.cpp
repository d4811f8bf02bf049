#include <algorithm>
#include <cmath>
#include <vector>

#include "conform/mesh/face_index.hpp"
#include "face_index_box.hpp"

namespace conform::mesh {

using boxes::Ray;

namespace {

bool less_hit(const SegmentHit& a, const SegmentHit& b) {
  return a.t < b.t || (a.t == b.t && a.face < b.face);
}

}  // namespace

bool segment_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& c, double& t,
                      std::array<double, 3>& bary) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (!(std::abs(det) > 1e-300)) return false;
  const double inv = 1 / det;
  const Eigen::Vector3d s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double tt = inv * e2.dot(qv);
  if (tt < 0 || tt > 1) return false;
  t = tt;
  bary = {1 - u - v, u, v};
  return true;
}

std::vector<SegmentHit> scan_segment_hits(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                                          const Eigen::Vector3d& q) {
  std::vector<SegmentHit> out;
  for (std::int32_t f = 0; f < mesh.face_count(); ++f) {
    const Face& t = mesh.faces[static_cast<std::size_t>(f)];
    SegmentHit h{f};
    if (segment_triangle(p, q, mesh.current.col(t[0]), mesh.current.col(t[1]),
                         mesh.current.col(t[2]), h.t, h.bary))
      out.push_back(h);
  }
  std::sort(out.begin(), out.end(), less_hit);
  return out;
}

void FaceIndex::segment_hits(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& q, std::vector<SegmentHit>& out) const {
  out.clear();
  if (nodes_.empty()) return;
  const Ray ray(p, q);
  std::vector<std::int32_t> stack;
  stack.reserve(64);
  stack.push_back(0);
  while (!stack.empty()) {
    const Node& n = nodes_[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    double enter = 0;
    if (!ray.hits(n.box, 1.0, enter)) continue;
    if (n.child >= 0) {
      stack.push_back(n.child + 1);
      stack.push_back(n.child);
      continue;
    }
    for (std::int32_t i = 0; i < n.count; ++i) {
      const std::int32_t f = items_[static_cast<std::size_t>(n.first + i)];
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      SegmentHit h{f};
      if (segment_triangle(p, q, mesh.current.col(t[0]), mesh.current.col(t[1]),
                           mesh.current.col(t[2]), h.t, h.bary))
        out.push_back(h);
    }
  }
  std::sort(out.begin(), out.end(), less_hit);
}

SegmentHit FaceIndex::first_hit(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                                const Eigen::Vector3d& q) const {
  SegmentHit best;
  if (nodes_.empty()) return best;
  const Ray ray(p, q);
  double tmax = 1;
  struct Entry {
    std::int32_t node;
    double enter;
  };
  std::vector<Entry> stack;
  stack.reserve(64);
  double enter = 0;
  if (ray.hits(nodes_[0].box, tmax, enter)) stack.push_back({0, enter});
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.enter > tmax) continue;
    const Node& n = nodes_[static_cast<std::size_t>(e.node)];
    if (n.child >= 0) {
      double t0 = 0, t1 = 0;
      const bool h0 = ray.hits(nodes_[static_cast<std::size_t>(n.child)].box, tmax, t0);
      const bool h1 = ray.hits(nodes_[static_cast<std::size_t>(n.child + 1)].box, tmax, t1);
      // The nearer child is popped first.
      if (h0 && h1) {
        if (t0 <= t1) {
          stack.push_back({n.child + 1, t1});
          stack.push_back({n.child, t0});
        } else {
          stack.push_back({n.child, t0});
          stack.push_back({n.child + 1, t1});
        }
      } else if (h0) {
        stack.push_back({n.child, t0});
      } else if (h1) {
        stack.push_back({n.child + 1, t1});
      }
      continue;
    }
    for (std::int32_t i = 0; i < n.count; ++i) {
      const std::int32_t f = items_[static_cast<std::size_t>(n.first + i)];
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      SegmentHit h{f};
      if (segment_triangle(p, q, mesh.current.col(t[0]), mesh.current.col(t[1]),
                           mesh.current.col(t[2]), h.t, h.bary) &&
          (best.face < 0 || less_hit(h, best))) {
        best = h;
        tmax = h.t;
      }
    }
  }
  return best;
}

}  // namespace conform::mesh
