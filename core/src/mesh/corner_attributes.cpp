#include "conform/mesh/corner_attributes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

void make_corner_attributes(SkinnedMesh& mesh) {
  const std::int32_t nf = mesh.face_count();
  if (mesh.has_uvs()) {
    mesh.corner_uvs.resize(6, nf);
    for (std::int32_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k)
        mesh.corner_uvs.col(f).segment<2>(2 * k) =
            mesh.uvs.col(mesh.faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)]);
  }
  if (mesh.has_normals()) {
    mesh.corner_normals.resize(9, nf);
    for (std::int32_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k)
        mesh.corner_normals.col(f).segment<3>(3 * k) =
            mesh.normals.col(mesh.faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)]);
  }
}

Eigen::Vector2d planar_uv(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  Eigen::Index least = 0;
  n.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d eu = n.cross(Eigen::Vector3d::Unit(least)).normalized();
  const Eigen::Vector3d ev = n.cross(eu);
  return {p.dot(eu), p.dot(ev)};
}

namespace {

// The base vertices a vertex descends from (itself for a base vertex), and the base vertex a
// vertex duplicates (following duplicates only; −1 when it is an interpolated vertex).
struct Ancestry {
  std::int32_t base = 0;
  std::vector<std::vector<std::int32_t>> roots;  // of new vertex i
  std::vector<std::int32_t> alias;               // of new vertex i

  Ancestry(const TopologyChange& change) : base(change.base_vertex_count) {
    const std::size_t n = change.new_vertices.size();
    roots.resize(n);
    alias.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      const NewVertex& v = change.new_vertices[i];
      auto& r = roots[i];
      for (int k = 0; k < 3; ++k)
        if (v.parents[k] >= 0 && v.coefficients[k] != 0)
          for (const std::int32_t p : roots_of(v.parents[k]))
            if (std::find(r.begin(), r.end(), p) == r.end() && r.size() < 16) r.push_back(p);
      if (v.is_duplicate()) alias[i] = alias_of(v.parents[0]);
    }
  }
  std::vector<std::int32_t> roots_of(std::int32_t v) const {
    return v < base ? std::vector<std::int32_t>{v} : roots[static_cast<std::size_t>(v - base)];
  }
  std::int32_t alias_of(std::int32_t v) const {
    return v < base ? v : alias[static_cast<std::size_t>(v - base)];
  }
};

Eigen::Vector3d rest_at(const SkinnedMesh& mesh, std::int32_t v) {
  return mesh.rest.col(v);
}

// Barycentric coordinates of the point of triangle (a, b, c) closest to p in its plane,
// clamped to the triangle and renormalized, and p's distance to the triangle.
std::pair<Eigen::Vector3d, double> closest_barycentric(const Eigen::Vector3d& p,
                                                       const Eigen::Vector3d& a,
                                                       const Eigen::Vector3d& b,
                                                       const Eigen::Vector3d& c) {
  const Eigen::Vector3d e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double det = d00 * d11 - d01 * d01;
  if (!(det > 0)) return {Eigen::Vector3d(1, 0, 0), (p - a).norm()};
  const double s = (d11 * d.dot(e0) - d01 * d.dot(e1)) / det;
  const double t = (d00 * d.dot(e1) - d01 * d.dot(e0)) / det;
  Eigen::Vector3d w(1 - s - t, s, t);
  w = w.cwiseMax(0.0);
  w /= w.sum();
  return {w, (p - (w[0] * a + w[1] * b + w[2] * c)).norm()};
}

struct OriginSearch {
  const SkinnedMesh& mesh;
  const TopologyChange& change;
  Ancestry ancestry;
  std::vector<std::pair<std::int32_t, std::int32_t>> incident;  // (base vertex, removed face)

  OriginSearch(const SkinnedMesh& m, const TopologyChange& c) : mesh(m), change(c), ancestry(c) {
    for (const std::int32_t f : change.removed_faces)
      for (const std::int32_t v : mesh.faces[static_cast<std::size_t>(f)])
        incident.push_back({v, f});
    std::sort(incident.begin(), incident.end());
  }

  // The removed face the added face `face` lies in, or −1 (new surface).
  std::int32_t origin(const Face& face) const {
    const Eigen::Vector3d a = rest_at(mesh, face[0]), b = rest_at(mesh, face[1]),
                          c = rest_at(mesh, face[2]);
    const Eigen::Vector3d centroid = (a + b + c) / 3, cross = (b - a).cross(c - a);
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const bool has_normal = cross.norm() > 1e-12 * longest * longest;
    const Eigen::Vector3d normal = has_normal ? Eigen::Vector3d(cross.normalized()) : cross;
    std::int32_t best = -1;
    double best_distance = 0.05 * longest;
    for (const std::int32_t corner : face)
      for (const std::int32_t root : ancestry.roots_of(corner)) {
        auto it = std::lower_bound(incident.begin(), incident.end(), std::pair{root, -1});
        for (; it != incident.end() && it->first == root; ++it) {
          const Face& f = mesh.faces[static_cast<std::size_t>(it->second)];
          const Eigen::Vector3d fa = rest_at(mesh, f[0]), fb = rest_at(mesh, f[1]),
                                fc = rest_at(mesh, f[2]);
          const Eigen::Vector3d fn = (fb - fa).cross(fc - fa);
          if (has_normal && !(fn.dot(normal) > 0.5 * fn.norm())) continue;
          const double distance = closest_barycentric(centroid, fa, fb, fc).second;
          if (distance < best_distance ||
              (distance == best_distance && best >= 0 && it->second < best)) {
            best_distance = distance;
            best = it->second;
          }
        }
      }
    return best;
  }
};

// Corner k of added face `face` interpolated in its origin face `f`: the weights of f's three
// corners (exactly one corner when the vertex is, or duplicates, one of f's vertices).
Eigen::Vector3d corner_weights(const OriginSearch& s, const Face& face, int k, std::int32_t f) {
  const Face& o = s.mesh.faces[static_cast<std::size_t>(f)];
  const std::int32_t v = face[static_cast<std::size_t>(k)], alias = s.ancestry.alias_of(v);
  for (int j = 0; j < 3; ++j)
    if (o[static_cast<std::size_t>(j)] == v || o[static_cast<std::size_t>(j)] == alias)
      return Eigen::Vector3d::Unit(j);
  return closest_barycentric(rest_at(s.mesh, v), rest_at(s.mesh, o[0]), rest_at(s.mesh, o[1]),
                             rest_at(s.mesh, o[2]))
      .first;
}

void new_surface(const SkinnedMesh& mesh, const Face& face, AddedCorners& out, std::size_t k) {
  const Eigen::Vector3d a = rest_at(mesh, face[0]), b = rest_at(mesh, face[1]),
                        c = rest_at(mesh, face[2]);
  Eigen::Vector3d n = (b - a).cross(c - a);
  n = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  const auto col = static_cast<Eigen::Index>(k);
  for (int j = 0; j < 3; ++j) {
    if (out.uvs.cols() > 0)
      out.uvs.col(col).segment<2>(2 * j) =
          planar_uv(rest_at(mesh, face[static_cast<std::size_t>(j)]), n);
    if (out.normals.cols() > 0) out.normals.col(col).segment<3>(3 * j) = n;
  }
}

}  // namespace

AddedCorners added_corner_attributes(const SkinnedMesh& mesh, const TopologyChange& change) {
  AddedCorners out;
  const bool uvs = mesh.has_corner_uvs(), normals = mesh.has_corner_normals();
  const auto na = static_cast<Eigen::Index>(change.added_faces.size());
  if (!uvs && !normals) return out;
  if (uvs) out.uvs.resize(6, na);
  if (normals) out.normals.resize(9, na);
  out.origin.assign(change.added_faces.size(), -1);
  const OriginSearch search(mesh, change);
  for (std::size_t i = 0; i < change.added_faces.size(); ++i) {
    const Face& face = change.added_faces[i];
    const std::int32_t f = search.origin(face);
    out.origin[i] = f;
    if (f < 0) {
      new_surface(mesh, face, out, i);
      continue;
    }
    const auto col = static_cast<Eigen::Index>(i);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d w = corner_weights(search, face, k, f);
      if (uvs) {
        Eigen::Vector2d uv = Eigen::Vector2d::Zero();
        for (int j = 0; j < 3; ++j)
          if (w[j] != 0) uv += w[j] * mesh.corner_uvs.col(f).segment<2>(2 * j);
        out.uvs.col(col).segment<2>(2 * k) = uv;
      }
      if (normals) {
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        for (int j = 0; j < 3; ++j)
          if (w[j] != 0) n += w[j] * mesh.corner_normals.col(f).segment<3>(3 * j);
        const double length = n.norm();
        out.normals.col(col).segment<3>(3 * k) =
            length > 1e-300 ? Eigen::Vector3d(n / length)
                            : Eigen::Vector3d(mesh.corner_normals.col(f).segment<3>(0));
      }
    }
  }
  return out;
}

std::vector<std::int32_t> added_face_origins(const SkinnedMesh& mesh,
                                             const TopologyChange& change) {
  const OriginSearch search(mesh, change);
  std::vector<std::int32_t> origin(change.added_faces.size());
  for (std::size_t i = 0; i < origin.size(); ++i) origin[i] = search.origin(change.added_faces[i]);
  return origin;
}

}  // namespace conform::mesh
