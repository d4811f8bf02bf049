#include "conform/mesh/topology_change.hpp"

#include "conform/mesh/detail/apply_steps.hpp"

#include "conform/mesh/corner_attributes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace conform::mesh {

std::string TopologyChange::validate() const {
  if (base_vertex_count < 0 || base_face_count < 0) return "negative base counts";
  const std::int64_t nv = std::int64_t(base_vertex_count) + std::int64_t(new_vertices.size());
  for (std::size_t i = 0; i < new_vertices.size(); ++i) {
    const NewVertex& v = new_vertices[i];
    const std::int64_t self = std::int64_t(base_vertex_count) + std::int64_t(i);
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      if (v.parents[k] < 0) {
        if (k == 0) return "new vertex " + std::to_string(i) + " has no parent";
        if (v.coefficients[k] != 0)
          return "new vertex " + std::to_string(i) + ": coefficient without parent";
        continue;
      }
      if (v.parents[k] >= self)
        return "new vertex " + std::to_string(i) + " refers to a later vertex";
      if (!std::isfinite(v.coefficients[k]))
        return "new vertex " + std::to_string(i) + ": non-finite coefficient";
      sum += v.coefficients[k];
    }
    if (std::abs(sum - 1) > 1e-12)
      return "new vertex " + std::to_string(i) + ": coefficients do not sum to 1";
    if (!v.displacement.allFinite())
      return "new vertex " + std::to_string(i) + ": non-finite displacement";
  }
  for (std::size_t i = 0; i < removed_faces.size(); ++i) {
    if (removed_faces[i] < 0 || removed_faces[i] >= base_face_count)
      return "removed face out of range";
    if (i > 0 && removed_faces[i] <= removed_faces[i - 1])
      return "removed faces not strictly increasing";
  }
  for (const Face& f : added_faces) {
    for (auto v : f)
      if (v < 0 || v >= nv) return "added face refers to a vertex out of range";
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return "added face repeats a vertex";
  }
  std::int64_t covered = 0;  // added faces before the next run may start
  for (const NewSurface& run : new_surface) {
    if (run.first < covered || run.count < 0 ||
        std::int64_t(run.first) + run.count > std::int64_t(added_faces.size()))
      return "new surface run out of range or overlapping";
    if (run.kind != FaceKind::skin && run.kind != FaceKind::cap && run.kind != FaceKind::tube)
      return "new surface of unknown kind";
    covered = std::int64_t(run.first) + run.count;
  }
  if (edit > EditKind::other) return "a change of unknown edit kind";
  return {};
}

std::int32_t TopologyChange::face_after(std::int32_t f) const {
  if (std::binary_search(removed_faces.begin(), removed_faces.end(), f))
    return -1;  // even a refilled slot now holds an added face, not f
  // A base face moves only in step 3, when it is the last face as a slot is filled.
  struct Follow {
    std::int32_t where;
    void fill(std::int32_t, std::size_t) {}
    void append(std::int32_t, std::size_t) {}
    void move(std::int32_t last, std::int32_t slot) {
      if (where == last) where = slot;
    }
    void pop(std::int32_t) {}
  } follow{f};
  visit_face_slots(*this, follow);
  return follow.where;
}

void blend_influences(SkinnedMesh& mesh, const std::array<std::int32_t, 3>& parents,
                      const std::array<double, 3>& coefficients, std::int32_t out) {
  std::array<std::int32_t, 3 * kMaxInfluences> bone{};
  std::array<double, 3 * kMaxInfluences> weight{};
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    if (parents[k] < 0 || coefficients[k] == 0) continue;
    for (int j = 0; j < kMaxInfluences; ++j) {
      const double w = mesh.weights(j, parents[k]);
      if (w == 0) continue;
      const std::int32_t b = mesh.bones(j, parents[k]);
      int i = 0;
      while (i < n && bone[i] != b) ++i;
      if (i == n) bone[n] = b, weight[n] = 0, ++n;
      weight[i] += coefficients[k] * w;
    }
  }
  std::array<int, 3 * kMaxInfluences> order{};
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.begin() + n, [&](int a, int b) {
    return weight[a] > weight[b] || (weight[a] == weight[b] && bone[a] < bone[b]);
  });
  const int keep = std::min(n, kMaxInfluences);
  double sum = 0;
  for (int i = 0; i < keep; ++i) sum += std::max(0.0, weight[order[i]]);
  for (int j = 0; j < kMaxInfluences; ++j) {
    if (j < keep && sum > 0 && weight[order[j]] > 0) {
      mesh.bones(j, out) = bone[order[j]];
      mesh.weights(j, out) = weight[order[j]] / sum;
    } else {
      mesh.bones(j, out) = 0;
      mesh.weights(j, out) = 0;
    }
  }
}

void apply(SkinnedMesh& mesh, const TopologyChange& change, Adjacency* adjacency) {
  if (change.base_vertex_count != mesh.vertex_count() ||
      change.base_face_count != mesh.face_count())
    throw std::invalid_argument("apply: the change was computed for a mesh of other counts");
  if (adjacency && !adjacency->matches(mesh))
    throw std::invalid_argument("apply: the adjacency does not describe this mesh");
  if (const std::string problem = change.validate(); !problem.empty())
    throw std::invalid_argument("apply: " + problem);
  if (!mesh.face_tags.empty() && mesh.face_tags.size() != mesh.faces.size())
    throw std::invalid_argument("apply: the mesh has " + std::to_string(mesh.face_tags.size()) +
                                " face tags for " + std::to_string(mesh.faces.size()) + " faces");
  detail::apply_vertices(mesh, change);
  detail::apply_faces(mesh, change, adjacency);
}

namespace detail {

void apply_vertices(SkinnedMesh& mesh, const TopologyChange& change) {
  // Vertices: grow every per-vertex array, then fill the new columns in order (a new vertex may
  // have earlier new vertices as parents).
  const std::int32_t nv0 = mesh.vertex_count();
  const auto nnew = static_cast<std::int32_t>(change.new_vertices.size());
  const std::int32_t nv = nv0 + nnew;
  const bool uvs = mesh.has_uvs(), normals = mesh.has_normals();
  const bool skin = mesh.bones.cols() == nv0 && mesh.weights.cols() == nv0;
  if (nnew > 0) {
    mesh.rest.conservativeResize(3, nv);
    mesh.current.conservativeResize(3, nv);
    if (skin)
      mesh.bones.conservativeResize(kMaxInfluences, nv),
          mesh.weights.conservativeResize(kMaxInfluences, nv);
    if (uvs) mesh.uvs.conservativeResize(2, nv);
    if (normals) mesh.normals.conservativeResize(3, nv);
    for (std::int32_t i = 0; i < nnew; ++i) {
      const NewVertex& v = change.new_vertices[static_cast<std::size_t>(i)];
      const std::int32_t o = nv0 + i;
      Eigen::Vector3d rest = Eigen::Vector3d::Zero(), cur = Eigen::Vector3d::Zero(),
                      n = Eigen::Vector3d::Zero();
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) {
        if (v.parents[k] < 0) continue;
        const double c = v.coefficients[k];
        rest += c * mesh.rest.col(v.parents[k]);
        cur += c * mesh.current.col(v.parents[k]);
        if (uvs) uv += c * mesh.uvs.col(v.parents[k]);
        if (normals) n += c * mesh.normals.col(v.parents[k]);
      }
      mesh.rest.col(o) = rest;
      mesh.current.col(o) = cur + v.displacement;
      if (uvs) mesh.uvs.col(o) = uv;
      if (normals) {
        const double len = n.norm();
        mesh.normals.col(o) = len > 1e-300 ? Eigen::Vector3d(n / len)
                                           : Eigen::Vector3d(mesh.normals.col(v.parents[0]));
      }
      if (skin) blend_influences(mesh, v.parents, v.coefficients, o);
    }
  }
}

// The tags of the added faces (skinned_mesh.hpp's rule): new surface as listed, every other
// face the kind of its origin. The origin search only runs when a removed face is not skin
// (otherwise every origin is skin); `origins` is the corner attributes' when they ran.
static std::vector<FaceTag> added_face_tags(const SkinnedMesh& mesh, const TopologyChange& change,
                                            const std::vector<std::int32_t>& origins) {
  const FaceTag made{FaceKind::skin, mesh.edits + 1,
                     change.edit == EditKind::model ? EditKind::other : change.edit};
  std::vector<FaceTag> tags(change.added_faces.size(), made);
  const bool inherit = std::any_of(
      change.removed_faces.begin(), change.removed_faces.end(),
      [&](std::int32_t f) { return mesh.face_tags[std::size_t(f)].kind != FaceKind::skin; });
  if (inherit) {
    const std::vector<std::int32_t> searched =
        origins.empty() ? added_face_origins(mesh, change) : std::vector<std::int32_t>{};
    const std::vector<std::int32_t>& origin = origins.empty() ? searched : origins;
    for (std::size_t k = 0; k < tags.size(); ++k)
      if (origin[k] >= 0) tags[k].kind = mesh.face_tags[std::size_t(origin[k])].kind;
  }
  for (const NewSurface& run : change.new_surface)
    for (std::int32_t k = run.first; k < run.first + run.count; ++k)
      tags[std::size_t(k)].kind = run.kind;
  return tags;
}

void apply_faces(SkinnedMesh& mesh, const TopologyChange& change, Adjacency* adjacency) {
  const auto& added = change.added_faces;
  // The added faces' corner attributes and tags, computed while the removed faces are there.
  const AddedCorners corners = added_corner_attributes(mesh, change);
  if (mesh.face_tags.size() != mesh.faces.size()) mesh.face_tags.assign(mesh.faces.size(), {});
  const std::vector<FaceTag> tags = added_face_tags(mesh, change, corners.origin);
  ++mesh.edits;
  const bool corner_uvs = mesh.has_corner_uvs(), corner_normals = mesh.has_corner_normals();
  if (adjacency)
    for (auto f : change.removed_faces) adjacency->remove_face(mesh, f);
  const std::size_t filled = std::min(change.removed_faces.size(), added.size());
  struct Slots {
    SkinnedMesh& mesh;
    Adjacency* adjacency;
    const std::vector<Face>& added;
    std::size_t filled;
    const AddedCorners& corners;
    const std::vector<FaceTag>& tags;
    bool uvs, normals;
    // The corner attributes follow their face through every slot operation.
    void set_corners(std::int32_t slot, std::size_t k) {
      const auto col = static_cast<Eigen::Index>(k);
      if (uvs) mesh.corner_uvs.col(slot) = corners.uvs.col(col);
      if (normals) mesh.corner_normals.col(slot) = corners.normals.col(col);
    }
    void resize_corners(std::int32_t faces) {
      if (uvs) mesh.corner_uvs.conservativeResize(6, faces);
      if (normals) mesh.corner_normals.conservativeResize(9, faces);
    }
    void fill(std::int32_t slot, std::size_t k) {
      mesh.faces[static_cast<std::size_t>(slot)] = added[k];
      mesh.face_tags[static_cast<std::size_t>(slot)] = tags[k];
      set_corners(slot, k);
      if (adjacency) adjacency->add_face(mesh, slot);
    }
    void append(std::int32_t slot, std::size_t k) {
      // Size the adjacency's half-edge array once for all appended faces rather than face by
      // face. (The face array keeps std::vector's doubling: reserving its exact size instead
      // measured 2x slower cuts on the arm, glibc then returning and re-faulting the heap's top
      // pages on every cut.)
      if (k == filled && adjacency)
        adjacency->resize_faces(
            static_cast<std::int32_t>(mesh.faces.size() + (added.size() - filled)));
      mesh.faces.push_back(added[k]);
      mesh.face_tags.push_back(tags[k]);
      resize_corners(mesh.face_count());
      set_corners(slot, k);
      if (adjacency) adjacency->add_face(mesh, slot);
    }
    void move(std::int32_t last, std::int32_t slot) {
      mesh.faces[static_cast<std::size_t>(slot)] = mesh.faces.back();
      mesh.face_tags[static_cast<std::size_t>(slot)] = mesh.face_tags.back();
      if (uvs) mesh.corner_uvs.col(slot) = mesh.corner_uvs.col(last);
      if (normals) mesh.corner_normals.col(slot) = mesh.corner_normals.col(last);
      if (adjacency) adjacency->move_face(mesh, last, slot);
    }
    void pop(std::int32_t) {
      mesh.faces.pop_back();
      mesh.face_tags.pop_back();
      resize_corners(mesh.face_count());
      if (adjacency) adjacency->resize_faces(mesh.face_count());
    }
  };
  visit_face_slots(
      change, Slots{mesh, adjacency, added, filled, corners, tags, corner_uvs, corner_normals});
}

}  // namespace detail

}  // namespace conform::mesh
