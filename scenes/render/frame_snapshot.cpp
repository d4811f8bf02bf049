#include "render/frame_snapshot.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace conform::scenes {

namespace {

Eigen::Matrix3Xd vertex_normals(const Eigen::Matrix3Xd& x, const std::vector<mesh::Face>& faces) {
  Eigen::Matrix3Xd n = Eigen::Matrix3Xd::Zero(3, x.cols());
  for (const auto& f : faces) {
    // The cross product's length is twice the area: larger faces weigh more.
    const Eigen::Vector3d a = (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0]));
    for (const auto v : f) n.col(v) += a;
  }
  for (Eigen::Index v = 0; v < n.cols(); ++v) {
    const double len = n.col(v).norm();
    n.col(v) = len > 0 ? Eigen::Vector3d(n.col(v) / len) : Eigen::Vector3d::UnitZ();
  }
  return n;
}

// Per-vertex UVs; a welded import keeps them per corner, where the first corner's wins.
Eigen::Matrix2Xd vertex_uvs(const mesh::SkinnedMesh& m) {
  Eigen::Matrix2Xd uv = Eigen::Matrix2Xd::Zero(2, m.vertex_count());
  if (m.has_uvs()) return m.uvs;
  if (!m.has_corner_uvs()) return uv;
  std::vector<bool> seen(static_cast<std::size_t>(m.vertex_count()), false);
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto v = m.faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
      if (seen[static_cast<std::size_t>(v)]) continue;
      seen[static_cast<std::size_t>(v)] = true;
      uv.col(v) = m.corner_uvs.col(f).segment<2>(2 * k);
    }
  return uv;
}

// Calls visit(v, d) for each vertex v of either lip, d its distance to the nearest vertex of the
// other lip (a vertex on both lips is not its own neighbour).
template <class Visit>
void across_lips(const Eigen::Matrix3Xd& x, const Lips& lips, Visit visit) {
  const auto side = [&](const std::vector<std::int32_t>& from,
                        const std::vector<std::int32_t>& to) {
    for (const auto v : from) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto w : to)
        if (w != v) best = std::min(best, (x.col(v) - x.col(w)).norm());
      if (std::isfinite(best)) visit(v, best);
    }
  };
  side(lips.left, lips.right);
  side(lips.right, lips.left);
}

}  // namespace

std::vector<double> edge_stretch(const mesh::SkinnedMesh& m) {
  const auto n = static_cast<std::size_t>(m.vertex_count());
  std::vector<double> sum(n, 0.0), count(n, 0.0);
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) {
      // Each interior edge is seen from both faces: both ends get it twice, which the mean
      // does not mind.
      const auto a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 3)];
      const double rest = (m.rest.col(a) - m.rest.col(b)).norm();
      if (!(rest > 0)) continue;
      const double strain = (m.current.col(a) - m.current.col(b)).norm() / rest - 1;
      for (const auto v : {a, b}) {
        sum[static_cast<std::size_t>(v)] += strain;
        count[static_cast<std::size_t>(v)] += 1;
      }
    }
  for (std::size_t v = 0; v < n; ++v) sum[v] = count[v] > 0 ? sum[v] / count[v] : 0.0;
  return sum;
}

std::vector<double> gap_width(const Eigen::Matrix3Xd& x, const Lips& lips) {
  std::vector<double> gap(static_cast<std::size_t>(x.cols()), 0.0);
  across_lips(x, lips, [&](std::int32_t v, double d) { gap[static_cast<std::size_t>(v)] = d; });
  return gap;
}

double largest_gap(const Eigen::Matrix3Xd& x, const Lips& lips) {
  if (lips.left.empty() || lips.right.empty()) return std::nan("");
  double largest = 0;
  across_lips(x, lips, [&](std::int32_t, double d) { largest = std::max(largest, d); });
  return largest;
}

FrameSnapshot snapshot(const std::string& name, int step, double time, const mesh::SkinnedMesh& m,
                       const Lips& lips, const std::string& scalar) {
  FrameSnapshot s;
  s.name = name;
  s.step = step;
  s.time = time;
  s.positions = m.current;
  s.faces = m.faces;
  s.normals = vertex_normals(s.positions, s.faces);
  s.uvs = vertex_uvs(m);
  for (const auto* side : {&lips.left, &lips.right})
    for (const auto v : *side) {
      if (v < 0 || v >= m.vertex_count())
        throw std::out_of_range("snapshot " + name + ": lip vertex " + std::to_string(v) +
                                " is not in the mesh's " + std::to_string(m.vertex_count()));
      s.focus.push_back(v);
    }
  s.wound = largest_gap(s.positions, lips);
  s.scalar = scalar == "gap" ? gap_width(s.positions, lips) : edge_stretch(m);
  return s;
}

}  // namespace conform::scenes
