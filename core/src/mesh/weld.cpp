#include "conform/mesh/weld.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "conform/mesh/corner_attributes.hpp"

namespace conform::mesh {

namespace {

double rest_diagonal(const SkinnedMesh& mesh) {
  if (mesh.vertex_count() == 0) return 0;
  return (mesh.rest.rowwise().maxCoeff() - mesh.rest.rowwise().minCoeff()).norm();
}

// The largest difference of one bone's weight between vertices a and b.
double weight_difference(const SkinnedMesh& mesh, std::int32_t a, std::int32_t b) {
  auto weight_of = [&](std::int32_t v, std::int32_t bone) {
    for (int j = 0; j < kMaxInfluences; ++j)
      if (mesh.weights(j, v) != 0 && mesh.bones(j, v) == bone) return mesh.weights(j, v);
    return 0.0;
  };
  double worst = 0;
  for (const auto& [u, w] : {std::pair{a, b}, std::pair{b, a}})
    for (int j = 0; j < kMaxInfluences; ++j)
      if (mesh.weights(j, u) != 0)
        worst = std::max(worst, std::abs(mesh.weights(j, u) - weight_of(w, mesh.bones(j, u))));
  return worst;
}

// Kept vertices by grid cell (cell size = the absolute tolerance).
struct Grid {
  double cell;
  struct Hash {
    std::size_t operator()(const Eigen::Array3i& k) const {
      return std::size_t(k[0]) * 73856093u ^ std::size_t(k[1]) * 19349663u ^
             std::size_t(k[2]) * 83492791u;
    }
  };
  struct Equal {
    bool operator()(const Eigen::Array3i& a, const Eigen::Array3i& b) const {
      return (a == b).all();
    }
  };
  std::unordered_map<Eigen::Array3i, std::vector<std::int32_t>, Hash, Equal> cells;

  Eigen::Array3i key(const Eigen::Vector3d& p) const {
    return (p.array() / cell).floor().cast<int>();
  }
};

// The greedy matching: result.vertex_map[v] = the kept vertex v joins (an old index, for now).
void match(const SkinnedMesh& mesh, const WeldOptions& options, std::span<const std::int32_t> group,
           WeldResult& result) {
  const std::int32_t nv = mesh.vertex_count();
  const double tolerance = options.tolerance * rest_diagonal(mesh);
  // The grid's integer keys must not overflow: a coarser cell only costs more comparisons.
  const double extent = std::max(rest_diagonal(mesh), mesh.rest.cwiseAbs().maxCoeff());
  Grid grid{std::max({tolerance, extent * 1e-8, 1e-300}), {}};
  const bool skin = mesh.bones.cols() == nv && mesh.weights.cols() == nv;
  const bool mean = options.differing_weights == DifferingWeights::mean;
  result.vertex_map.assign(static_cast<std::size_t>(nv), -1);
  std::vector<std::uint8_t> differs(static_cast<std::size_t>(nv), 0);  // kept vertex → mean
  for (std::int32_t v = 0; v < nv; ++v) {
    const Eigen::Vector3d p = mesh.rest.col(v);
    const Eigen::Array3i k = grid.key(p);
    std::int32_t into = -1;
    bool near = false;
    double difference = 0;  // of the weights of `into`
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.cells.find(k + Eigen::Array3i(dx, dy, dz));
          if (it == grid.cells.end()) continue;
          for (const std::int32_t r : it->second) {
            if (!group.empty() && group[std::size_t(r)] != group[std::size_t(v)]) continue;
            if ((mesh.rest.col(r) - p).norm() > tolerance) continue;
            near = true;
            const double d = skin ? weight_difference(mesh, r, v) : 0;
            if (d > options.weight_tolerance && !mean) continue;
            if (into < 0 || r < into) into = r, difference = d;
          }
        }
    if (into >= 0) {
      result.vertex_map[std::size_t(v)] = into;
      ++result.merged;
      if (difference > options.weight_tolerance) {
        differs[std::size_t(into)] = 1;
        result.largest_weight_difference = std::max(result.largest_weight_difference, difference);
      }
    } else {
      result.vertex_map[std::size_t(v)] = v;
      result.kept_apart += near;
      grid.cells[k].push_back(v);
    }
  }
  for (std::int32_t v = 0; v < nv; ++v)
    if (differs[std::size_t(v)]) result.averaged.push_back(v);  // old ids, for now
}

// The mean of the influences of the vertices `copies`: per bone, the mean weight; the
// kMaxInfluences largest kept (ties: lower bone), scaled to the copies' mean weight sum.
void mean_influences(SkinnedMesh& mesh, std::int32_t into,
                     const std::vector<std::int32_t>& copies) {
  std::vector<std::pair<std::int32_t, double>> sum;  // (bone, summed weight)
  double total = 0;
  for (const std::int32_t c : copies)
    for (int j = 0; j < kMaxInfluences; ++j) {
      const double w = mesh.weights(j, c);
      if (w == 0) continue;
      total += w;
      const std::int32_t bone = mesh.bones(j, c);
      auto it =
          std::find_if(sum.begin(), sum.end(), [&](const auto& e) { return e.first == bone; });
      if (it == sum.end())
        sum.push_back({bone, w});
      else
        it->second += w;
    }
  std::sort(sum.begin(), sum.end(), [](const auto& a, const auto& b) {
    return a.second > b.second || (a.second == b.second && a.first < b.first);
  });
  if (sum.size() > std::size_t(kMaxInfluences)) sum.resize(std::size_t(kMaxInfluences));
  double kept = 0;
  for (const auto& e : sum) kept += e.second;
  const double scale = kept > 0 ? total / kept / double(copies.size()) : 0;
  for (int j = 0; j < kMaxInfluences; ++j) {
    const bool used = std::size_t(j) < sum.size();
    mesh.bones(j, into) = used ? sum[std::size_t(j)].first : 0;
    mesh.weights(j, into) = used ? sum[std::size_t(j)].second * scale : 0;
  }
}

// The welded vertices whose copies' weights differ take their mean (old indices still).
void average_differing_weights(SkinnedMesh& mesh, const WeldResult& result) {
  if (result.averaged.empty()) return;
  std::unordered_map<std::int32_t, std::vector<std::int32_t>> copies;
  for (const std::int32_t v : result.averaged) copies[v] = {};
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto it = copies.find(result.vertex_map[std::size_t(v)]);
    if (it != copies.end()) it->second.push_back(v);
  }
  for (const std::int32_t v : result.averaged) mean_influences(mesh, v, copies[v]);
}

// Keeps the columns `kept` (old indices, increasing) of a per-vertex array.
template <class Array>
void keep_columns(Array& a, const std::vector<std::int32_t>& kept, std::int32_t nv) {
  if (a.cols() != nv) return;
  for (std::size_t i = 0; i < kept.size(); ++i)
    if (kept[i] != std::int32_t(i)) a.col(Eigen::Index(i)) = a.col(kept[i]);
  a.conservativeResize(a.rows(), Eigen::Index(kept.size()));
}

void compact_vertices(SkinnedMesh& mesh, WeldResult& result) {
  const std::int32_t nv = mesh.vertex_count();
  std::vector<std::int32_t> renumber(std::size_t(nv), -1);
  for (std::int32_t v = 0; v < nv; ++v)
    if (result.vertex_map[std::size_t(v)] == v) {
      renumber[std::size_t(v)] = std::int32_t(result.kept.size());
      result.kept.push_back(v);
    }
  for (auto& m : result.vertex_map) m = renumber[std::size_t(m)];
  for (auto& a : result.averaged) a = renumber[std::size_t(a)];
  if (mesh.has_normals()) {  // a kept vertex's normal: its cluster's, summed
    Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, Eigen::Index(result.kept.size()));
    for (std::int32_t v = 0; v < nv; ++v)
      sum.col(result.vertex_map[std::size_t(v)]) += mesh.normals.col(v);
    for (std::size_t i = 0; i < result.kept.size(); ++i) {
      const double length = sum.col(Eigen::Index(i)).norm();
      if (length > 1e-300) mesh.normals.col(result.kept[i]) = sum.col(Eigen::Index(i)) / length;
    }
  }
  keep_columns(mesh.current, result.kept, nv);
  keep_columns(mesh.bones, result.kept, nv);
  keep_columns(mesh.weights, result.kept, nv);
  keep_columns(mesh.uvs, result.kept, nv);
  keep_columns(mesh.normals, result.kept, nv);
  keep_columns(mesh.rest, result.kept, nv);  // last: the others compare their size with it
}

void compact_faces(SkinnedMesh& mesh, WeldResult& result) {
  const bool uvs = mesh.has_corner_uvs(), normals = mesh.has_corner_normals();
  const std::int32_t nf = mesh.face_count();
  result.face_map.assign(std::size_t(nf), -1);
  std::int32_t out = 0;
  for (std::int32_t f = 0; f < nf; ++f) {
    Face face = mesh.faces[std::size_t(f)];
    for (auto& v : face) v = result.vertex_map[std::size_t(v)];
    if (face[0] == face[1] || face[1] == face[2] || face[0] == face[2]) {
      ++result.collapsed_faces;
      continue;
    }
    mesh.faces[std::size_t(out)] = face;
    if (uvs) mesh.corner_uvs.col(out) = mesh.corner_uvs.col(f);
    if (normals) mesh.corner_normals.col(out) = mesh.corner_normals.col(f);
    result.face_map[std::size_t(f)] = out++;
  }
  mesh.faces.resize(std::size_t(out));
  if (uvs) mesh.corner_uvs.conservativeResize(6, out);
  if (normals) mesh.corner_normals.conservativeResize(9, out);
}

}  // namespace

WeldResult weld(SkinnedMesh& mesh, const WeldOptions& options,
                std::span<const std::int32_t> group) {
  if (!(options.tolerance >= 0) || !(options.weight_tolerance >= 0))
    throw std::invalid_argument("weld: tolerances must be >= 0");
  if (!group.empty() && group.size() != std::size_t(mesh.vertex_count()))
    throw std::invalid_argument("weld: " + std::to_string(group.size()) + " groups for " +
                                std::to_string(mesh.vertex_count()) + " vertices");
  if (!mesh.has_corner_uvs() && !mesh.has_corner_normals()) make_corner_attributes(mesh);
  WeldResult result;
  match(mesh, options, group, result);
  average_differing_weights(mesh, result);
  compact_vertices(mesh, result);
  compact_faces(mesh, result);
  return result;
}

}  // namespace conform::mesh
