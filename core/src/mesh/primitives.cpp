#include "conform/mesh/primitives.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace conform::mesh {

namespace {

SkinnedMesh from_positions(const std::vector<Eigen::Vector3d>& p, std::vector<Face> faces) {
  SkinnedMesh m;
  const auto n = static_cast<Eigen::Index>(p.size());
  m.rest.resize(3, n);
  for (Eigen::Index i = 0; i < n; ++i) m.rest.col(i) = p[static_cast<std::size_t>(i)];
  m.current = m.rest;
  m.faces = std::move(faces);
  m.bones.setZero(kMaxInfluences, n);
  m.weights.setZero(kMaxInfluences, n);
  m.weights.row(0).setOnes();
  m.uvs.setZero(2, n);
  m.normals.setZero(3, n);
  return m;
}

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

}  // namespace

void assign_height_weights(SkinnedMesh& mesh, double z0, double z1, double blend) {
  const auto n = mesh.rest.cols();
  mesh.bones.setZero(kMaxInfluences, n);
  mesh.weights.setZero(kMaxInfluences, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double z = mesh.rest(2, i);
    const double a = smoothstep(z0 - blend, z0 + blend, z);  // 0 → bone 0, 1 → bone 1+
    const double b = smoothstep(z1 - blend, z1 + blend, z);  // 1 → bone 2
    double w[3] = {1 - a, a * (1 - b), a * b};
    int idx[3] = {0, 1, 2};
    std::sort(idx, idx + 3, [&](int x, int y) { return w[x] > w[y] || (w[x] == w[y] && x < y); });
    for (int k = 0; k < 3; ++k) {
      mesh.bones(k, i) = w[idx[k]] > 0 ? idx[k] : 0;
      mesh.weights(k, i) = w[idx[k]];
    }
  }
}

SkinnedMesh make_icosphere(int subdivisions, double radius) {
  if (subdivisions < 0 || subdivisions > 8)
    throw std::invalid_argument("icosphere: subdivisions in [0, 8]");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& x : p) x.normalize();
  std::vector<Face> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                         {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                         {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                         {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[static_cast<std::size_t>(a)] + p[static_cast<std::size_t>(b)]).normalized());
      const int id = static_cast<int>(p.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<Face> g;
    g.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                c = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, c});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], c, b});
      g.push_back({a, b, c});
    }
    f = std::move(g);
  }
  std::vector<Eigen::Vector3d> q = p;
  for (auto& x : q) x *= radius;
  SkinnedMesh m = from_positions(q, std::move(f));
  for (Eigen::Index i = 0; i < m.rest.cols(); ++i) {
    const Eigen::Vector3d n = p[static_cast<std::size_t>(i)];
    m.normals.col(i) = n;
    m.uvs(0, i) = 0.5 + std::atan2(n.y(), n.x()) / (2 * std::numbers::pi);
    m.uvs(1, i) = 0.5 + std::asin(std::clamp(n.z(), -1.0, 1.0)) / std::numbers::pi;
  }
  assign_height_weights(m, -0.3 * radius, 0.3 * radius, 0.25 * radius);
  return m;
}

SkinnedMesh make_grid_sheet(const std::vector<double>& us, const std::vector<double>& vs,
                            const Eigen::Vector3d& u_axis, const Eigen::Vector3d& v_axis,
                            double uv_size) {
  const auto nu = static_cast<std::int32_t>(us.size()), nv = static_cast<std::int32_t>(vs.size());
  const std::int32_t count = nu * nv;
  SkinnedMesh m;
  m.rest.resize(3, count);
  m.bones.setZero(kMaxInfluences, count);
  m.weights.setZero(kMaxInfluences, count);
  m.uvs.resize(2, count);
  m.normals.resize(3, count);
  const Eigen::Vector3d normal = u_axis.cross(v_axis).normalized();
  const auto id = [nu](std::int32_t i, std::int32_t j) { return j * nu + i; };
  for (std::int32_t j = 0; j < nv; ++j)
    for (std::int32_t i = 0; i < nu; ++i) {
      const std::int32_t k = id(i, j);
      const double u = us[std::size_t(i)], v = vs[std::size_t(j)];
      m.rest.col(k) = u * u_axis + v * v_axis;
      m.weights(0, k) = 1;
      m.uvs.col(k) = Eigen::Vector2d(u / uv_size + 0.5, v / uv_size + 0.5);
      m.normals.col(k) = normal;
    }
  m.current = m.rest;
  for (std::int32_t j = 0; j + 1 < nv; ++j)
    for (std::int32_t i = 0; i + 1 < nu; ++i) {
      const std::int32_t p00 = id(i, j), p10 = id(i + 1, j), p01 = id(i, j + 1),
                         p11 = id(i + 1, j + 1);
      if ((i + j) % 2 == 0) {
        m.faces.push_back({p00, p10, p11});
        m.faces.push_back({p00, p11, p01});
      } else {
        m.faces.push_back({p00, p10, p01});
        m.faces.push_back({p10, p11, p01});
      }
    }
  return m;
}

SkinnedMesh make_sheet(int nx, int ny, double width, double height) {
  if (nx < 1 || ny < 1) throw std::invalid_argument("sheet: nx, ny ≥ 1");
  std::vector<Eigen::Vector3d> p;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      p.emplace_back(width * (double(i) / nx - 0.5), height * (double(j) / ny - 0.5), 0.0);
  std::vector<Face> f;
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // Alternate the diagonal so that the sheet has no preferred direction.
      if ((i + j) % 2 == 0) {
        f.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        f.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        f.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        f.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  SkinnedMesh m = from_positions(p, std::move(f));
  for (Eigen::Index i = 0; i < m.rest.cols(); ++i) {
    m.normals.col(i) = Eigen::Vector3d::UnitZ();
    m.uvs(0, i) = m.rest(0, i) / width + 0.5;
    m.uvs(1, i) = m.rest(1, i) / height + 0.5;
  }
  // Weights along y for a sheet (z is constant): reuse the z rule on a rotated copy.
  const Eigen::Matrix3Xd saved = m.rest;
  m.rest.row(2) = saved.row(1);
  assign_height_weights(m, -0.2 * height, 0.2 * height, 0.2 * height);
  m.rest = saved;
  return m;
}

SkinnedMesh make_cylinder(int segments, int rings, double radius, double length) {
  if (segments < 3 || rings < 1) throw std::invalid_argument("cylinder: segments ≥ 3, rings ≥ 1");
  std::vector<Eigen::Vector3d> p;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i < segments; ++i) {
      const double a = 2 * std::numbers::pi * i / segments;
      p.emplace_back(radius * std::cos(a), radius * std::sin(a), length * j / rings);
    }
  const int bottom = static_cast<int>(p.size());
  p.emplace_back(0, 0, 0);
  const int top = static_cast<int>(p.size());
  p.emplace_back(0, 0, length);
  std::vector<Face> f;
  auto id = [&](int i, int j) { return j * segments + (i % segments); };
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      f.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      f.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int i = 0; i < segments; ++i) {
    f.push_back({bottom, id(i + 1, 0), id(i, 0)});
    f.push_back({top, id(i, rings), id(i + 1, rings)});
  }
  SkinnedMesh m = from_positions(p, std::move(f));
  for (Eigen::Index i = 0; i < m.rest.cols(); ++i) {
    Eigen::Vector3d n(m.rest(0, i), m.rest(1, i), 0.0);
    if (i == bottom) n = -Eigen::Vector3d::UnitZ();
    if (i == top) n = Eigen::Vector3d::UnitZ();
    m.normals.col(i) = n.normalized();
    m.uvs(0, i) = 0.5 + std::atan2(m.rest(1, i), m.rest(0, i)) / (2 * std::numbers::pi);
    m.uvs(1, i) = m.rest(2, i) / length;
  }
  assign_height_weights(m, length / 3, 2 * length / 3, length / 8);
  return m;
}

}  // namespace conform::mesh
