#include "change_flips.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <utility>

#include "conform/mesh/analysis.hpp"

namespace conform::mesh {

namespace {

using Edge = std::pair<std::int32_t, std::int32_t>;

Edge key(std::int32_t u, std::int32_t v) {
  return u < v ? Edge{u, v} : Edge{v, u};
}

// The faces being flipped: the change's added faces, then the mesh faces beside them (with
// their slot), and each undirected edge's faces among them.
class FlipRegion {
 public:
  FlipRegion(const SkinnedMesh& mesh, const Adjacency& adjacency, const TopologyChange& change,
             const std::vector<std::int32_t>& slots = {})
      : mesh_(mesh), adjacency_(adjacency), change_(change) {
    for (const NewVertex& nv : change.new_vertices) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k)
        if (nv.parents[k] >= 0) x += nv.coefficients[k] * at(nv.parents[k]);
      added_.push_back(x);
    }
    for (const Face& f : change.added_faces) faces_.push_back({f, -1});
    removed_ = change.removed_faces;
    std::sort(removed_.begin(), removed_.end());
    for (const std::int32_t slot : slots)
      if (!std::binary_search(removed_.begin(), removed_.end(), slot) && !slot_seen(slot))
        faces_.push_back({mesh.faces[static_cast<std::size_t>(slot)], slot});
    for (std::size_t i = 0; i < faces_.size(); ++i) link(i, true);
    const std::size_t added = faces_.size();
    for (std::size_t i = 0; i < added; ++i) add_neighbors(i);
  }

  // The mesh faces across face i's edges, where not in the region yet (a flip that changed a
  // mesh face lets the flips go on beyond it).
  void add_neighbors(std::size_t i) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t u = faces_[i].f[k], v = faces_[i].f[(k + 1) % 3];
      if (u >= base() || v >= base()) continue;
      const std::int32_t h = adjacency_.find(v, u);
      if (h < 0) continue;
      const std::int32_t slot = h / 3;
      if (std::binary_search(removed_.begin(), removed_.end(), slot) || slot_seen(slot)) continue;
      faces_.push_back({mesh_.faces[static_cast<std::size_t>(slot)], slot});
      link(faces_.size() - 1, true);
    }
  }

  std::int32_t base() const { return change_.base_vertex_count; }
  Eigen::Vector3d at(std::int32_t v) const {
    return v < base() ? Eigen::Vector3d(mesh_.current.col(v))
                      : added_[static_cast<std::size_t>(v - base())];
  }
  double quality(const Face& f) const { return smallest_angle_sin2(at(f[0]), at(f[1]), at(f[2])); }

  struct LocalFace {
    Face f;
    std::int32_t slot;  // the mesh face it was, or −1 for one the change adds
    bool changed = false;
  };
  std::vector<LocalFace> faces_;
  std::map<Edge, std::vector<std::size_t>> edges_;

  // Adds (or removes) face i's edges to the edge map.
  void link(std::size_t i, bool add) {
    for (int k = 0; k < 3; ++k) {
      auto& list = edges_[key(faces_[i].f[k], faces_[i].f[(k + 1) % 3])];
      if (add) {
        list.push_back(i);
      } else {
        list.erase(std::remove(list.begin(), list.end(), i), list.end());
      }
    }
  }
  // Faces i (u → v, third vertex a) and j (v → u, third vertex b) become (u, b, a), (b, v, a).
  void flip(std::size_t i, std::size_t j, const Face& g1, const Face& g2) {
    link(i, false), link(j, false);
    faces_[i].f = g1, faces_[j].f = g2;
    faces_[i].changed = faces_[j].changed = true;
    link(i, true), link(j, true);
    add_neighbors(i), add_neighbors(j);
  }
  // The other face on face i's edge (u, v), or faces_.size(); `third` gets its third vertex
  // (when it runs v → u).
  std::size_t across(std::size_t i, std::int32_t u, std::int32_t v, std::int32_t& third) const {
    const auto it = edges_.find(key(u, v));
    if (it == edges_.end() || it->second.size() != 2) return faces_.size();
    const std::size_t j = it->second[0] == i ? it->second[1] : it->second[0];
    const Face& g = faces_[j].f;
    for (int m = 0; m < 3; ++m)
      if (g[m] == v && g[(m + 1) % 3] == u) return third = g[(m + 2) % 3], j;
    return faces_.size();
  }
  // Faces (u, v, a) and (v, u, b) turned to (u, b, a) and (b, v, a) still face the same way.
  bool convex(std::int32_t u, std::int32_t v, std::int32_t a, std::int32_t b) const {
    const Eigen::Vector3d pu = at(u), pv = at(v), pa = at(a), pb = at(b);
    const Eigen::Vector3d n =
        (pv - pu).cross(pa - pu).normalized() + (pu - pv).cross(pb - pv).normalized();
    return (pb - pu).cross(pa - pu).dot(n) > 0 && (pv - pb).cross(pa - pb).dot(n) > 0;
  }
  // The quad of faces (u, v, a) and (v, u, b) is nearly flat: its diagonals within max_bend of
  // the longer one of each other.
  bool flat(std::int32_t u, std::int32_t v, std::int32_t a, std::int32_t b,
            const FlipOptions& options) const {
    const Eigen::Vector3d d1 = at(v) - at(u), d2 = at(b) - at(a), c = d1.cross(d2);
    return c.norm() > 0 && std::abs((at(a) - at(u)).dot(c)) / c.norm() <=
                               options.max_bend * std::max(d1.norm(), d2.norm());
  }
  // The change with the flipped faces: the mesh faces a flip touched are removed and added.
  void write(TopologyChange& change) const {
    std::vector<Face> added;
    for (const auto& lf : faces_) {
      if (lf.slot >= 0 && !lf.changed) continue;
      if (lf.slot >= 0) change.removed_faces.push_back(lf.slot);
      added.push_back(lf.f);
    }
    change.added_faces = std::move(added);
    std::sort(change.removed_faces.begin(), change.removed_faces.end());
  }

  bool has_edge(std::int32_t u, std::int32_t v) const {
    const auto it = edges_.find(key(u, v));
    return it != edges_.end() && !it->second.empty();
  }

 private:
  bool slot_seen(std::int32_t slot) const {
    return std::any_of(faces_.begin(), faces_.end(),
                       [slot](const LocalFace& lf) { return lf.slot == slot; });
  }
  const SkinnedMesh& mesh_;
  const Adjacency& adjacency_;
  const TopologyChange& change_;
  std::vector<std::int32_t> removed_;  // sorted
  std::vector<Eigen::Vector3d> added_;
};

// Face f's corner attributes at vertex v (UVs then normals), or an empty vector.
std::vector<double> corner_of(const SkinnedMesh& mesh, std::int32_t face, std::int32_t v) {
  std::vector<double> out;
  const Face& f = mesh.faces[static_cast<std::size_t>(face)];
  const int k = f[0] == v ? 0 : (f[1] == v ? 1 : 2);
  if (mesh.has_corner_uvs())
    for (int i = 0; i < 2; ++i) out.push_back(mesh.corner_uvs(2 * k + i, face));
  if (mesh.has_corner_normals())
    for (int i = 0; i < 3; ++i) out.push_back(mesh.corner_normals(3 * k + i, face));
  return out;
}

// Edge (u, v) lies on a seam of the mesh's corner attributes: along a mesh edge whose two faces
// disagree at either end (also for a piece of such an edge, cut at a new vertex on it).
bool on_seam(const SkinnedMesh& mesh, const Adjacency& adjacency, const TopologyChange& change,
             std::int32_t u, std::int32_t v) {
  if (!mesh.has_corner_uvs() && !mesh.has_corner_normals()) return false;
  const std::int32_t base = change.base_vertex_count;
  if (u >= base) std::swap(u, v);
  if (u >= base) return false;  // two new vertices: inside a face
  if (v >= base) {              // a piece of the edge a new vertex lies on, if any
    const NewVertex& nv = change.new_vertices[static_cast<std::size_t>(v - base)];
    if (nv.parents[2] >= 0 || nv.parents[1] < 0) return false;
    if (nv.parents[0] != u && nv.parents[1] != u) return false;
    v = nv.parents[0] == u ? nv.parents[1] : nv.parents[0];
    if (v >= base) return false;
  }
  const std::int32_t h = adjacency.find(u, v), g = adjacency.find(v, u);
  if (h < 0 || g < 0) return false;
  return corner_of(mesh, h / 3, u) != corner_of(mesh, g / 3, u) ||
         corner_of(mesh, h / 3, v) != corner_of(mesh, g / 3, v);
}

}  // namespace

int flip_for_angles(const SkinnedMesh& mesh, const Adjacency& adjacency, TopologyChange& change,
                    const std::vector<std::array<std::int32_t, 2>>& fixed,
                    const FlipOptions& options) {
  FlipRegion r(mesh, adjacency, change);
  std::vector<Edge> kept;
  for (const auto& e : fixed) kept.push_back(key(e[0], e[1]));
  int flips = 0;
  for (bool again = true; again && flips < options.max_flips;) {
    again = false;
    std::vector<Edge> edges;
    for (const auto& [e, list] : r.edges_)
      if (list.size() == 2 && std::find(kept.begin(), kept.end(), e) == kept.end())
        edges.push_back(e);
    for (const Edge& e : edges) {
      const auto& list = r.edges_[e];
      if (list.size() != 2) continue;
      // Face i runs u → v, face j v → u; a and b are their third vertices.
      const std::size_t i = list[0];
      const Face fi = r.faces_[i].f;
      int k = 0;
      while (k < 3 && !(key(fi[k], fi[(k + 1) % 3]) == e)) ++k;
      const std::int32_t u = fi[k], v = fi[(k + 1) % 3], a = fi[(k + 2) % 3];
      std::int32_t b = -1;
      const std::size_t j = r.across(i, u, v, b);
      if (j == r.faces_.size() || a == b || r.has_edge(a, b) || adjacency.find(a, b) >= 0 ||
          adjacency.find(b, a) >= 0 || !r.convex(u, v, a, b) || !r.flat(u, v, a, b, options))
        continue;
      const Face g1{u, b, a}, g2{b, v, a};
      const double before = std::min(r.quality(fi), r.quality(r.faces_[j].f));
      const double after = std::min(r.quality(g1), r.quality(g2));
      if (!(after > before * (1 + 1e-9)) || on_seam(mesh, adjacency, change, u, v)) continue;
      r.flip(i, j, g1, g2);
      again = true;
      if (++flips >= options.max_flips) break;
    }
  }
  if (flips > 0) r.write(change);
  return flips;
}

bool flip_to_edge(const SkinnedMesh& mesh, const Adjacency& adjacency, TopologyChange& change,
                  std::int32_t t, std::int32_t p, const Eigen::Vector3d& normal,
                  const std::vector<std::int32_t>& slots, const FlipOptions& options) {
  FlipRegion r(mesh, adjacency, change, slots);
  const Eigen::Vector3d pt = r.at(t), along = r.at(p) - pt;
  auto side = [&](std::int32_t v) { return (r.at(v) - pt).dot(normal); };
  bool done = false;
  for (int flips = 0; flips <= options.max_flips; ++flips) {
    if (r.has_edge(t, p)) {
      done = true;
      break;
    }
    // The face at t whose opposite edge (a, b) the segment t → p crosses.
    std::size_t i = r.faces_.size();
    std::int32_t a = -1, b = -1;
    for (std::size_t f = 0; f < r.faces_.size() && i == r.faces_.size(); ++f) {
      const Face& g = r.faces_[f].f;
      for (int k = 0; k < 3; ++k) {
        if (g[k] != t) continue;
        const std::int32_t x = g[(k + 1) % 3], y = g[(k + 2) % 3];
        const double sx = side(x), sy = side(y);
        if (!(sx * sy < 0)) continue;
        const Eigen::Vector3d cross = r.at(x) + sx / (sx - sy) * (r.at(y) - r.at(x));
        if ((cross - pt).dot(along) > 0) i = f, a = x, b = y;
      }
    }
    if (i == r.faces_.size()) break;
    std::int32_t c = -1;
    const std::size_t j = r.across(i, a, b, c);
    if (j == r.faces_.size() || c == t || r.has_edge(t, c) || adjacency.find(t, c) >= 0 ||
        adjacency.find(c, t) >= 0 || !r.convex(a, b, t, c) || !r.flat(a, b, t, c, options) ||
        on_seam(mesh, adjacency, change, a, b))
      break;
    r.flip(i, j, {a, c, t}, {c, b, t});
  }
  r.write(change);
  return done;
}

}  // namespace conform::mesh
