#include "conform/io/model_check.hpp"

#include <cmath>
#include <limits>

namespace conform::io {
namespace {

std::string check_sizes(const mesh::SkinnedMesh& m) {
  const Eigen::Index v = m.rest.cols(), f = static_cast<Eigen::Index>(m.faces.size());
  const auto per_vertex = [v](Eigen::Index n, bool optional) {
    return n == v || (optional && n == 0);
  };
  if (!per_vertex(m.current.cols(), false)) return "mesh: current positions are not one per vertex";
  if (!per_vertex(m.bones.cols(), false) || !per_vertex(m.weights.cols(), false))
    return "mesh: influences are not one set per vertex";
  if (!per_vertex(m.uvs.cols(), true)) return "mesh: UVs are neither one per vertex nor absent";
  if (!per_vertex(m.normals.cols(), true))
    return "mesh: normals are neither one per vertex nor absent";
  if (m.corner_uvs.cols() != f && m.corner_uvs.cols() != 0)
    return "mesh: corner UVs are neither one set per face nor absent";
  if (m.corner_normals.cols() != f && m.corner_normals.cols() != 0)
    return "mesh: corner normals are neither one set per face nor absent";
  if (v >= std::numeric_limits<std::int32_t>::max() ||
      f >= std::numeric_limits<std::int32_t>::max())
    return "mesh: more vertices or faces than 32-bit indices hold";
  return {};
}

std::string check_mesh_values(const mesh::SkinnedMesh& m, std::int32_t bone_count) {
  if (auto e = check_sizes(m); !e.empty()) return e;
  const std::int32_t nv = m.vertex_count();
  for (std::size_t i = 0; i < m.faces.size(); ++i) {
    const mesh::Face& f = m.faces[i];
    for (const auto v : f)
      if (v < 0 || v >= nv)
        return "mesh face " + std::to_string(i) + " has vertex " + std::to_string(v) + " of " +
               std::to_string(nv);
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
      return "mesh face " + std::to_string(i) + " repeats a vertex";
  }
  if (!m.rest.allFinite() || !m.current.allFinite()) return "mesh: NaN or infinite positions";
  if (!m.uvs.allFinite() || !m.normals.allFinite() || !m.corner_uvs.allFinite() ||
      !m.corner_normals.allFinite())
    return "mesh: NaN or infinite UVs or normals";
  for (std::int32_t v = 0; v < nv; ++v)
    for (int k = 0; k < mesh::kMaxInfluences; ++k) {
      const std::int32_t b = m.bones(k, v);
      const double w = m.weights(k, v);
      if (b < 0 || b >= bone_count || !std::isfinite(w) || w < 0)
        return "mesh vertex " + std::to_string(v) + " has influence (bone " + std::to_string(b) +
               ", weight " + std::to_string(w) + "), out of range (" + std::to_string(bone_count) +
               " bones)";
    }
  return {};
}

std::string check_infos(const SkinnedModel& model) {
  const std::int64_t nv = model.mesh.vertex_count(), nf = model.mesh.face_count();
  const std::int32_t joints = model.skeleton.joint_count();
  for (std::size_t i = 0; i < model.meshes.size(); ++i) {
    const MeshInfo& m = model.meshes[i];
    const bool vertices = m.first_vertex >= 0 && m.vertex_count >= 0 &&
                          std::int64_t(m.first_vertex) + m.vertex_count <= nv;
    const bool faces =
        m.first_face >= 0 && m.face_count >= 0 && std::int64_t(m.first_face) + m.face_count <= nf;
    if (!vertices || !faces || m.joint < 0 || m.joint >= std::max(joints, 1) || m.bones < 0)
      return "mesh entry " + std::to_string(i) + " ('" + m.name +
             "') has a vertex, face or joint range outside the model";
  }
  return {};
}

}  // namespace

std::string check_model(const SkinnedModel& model) {
  const skin::Skeleton& s = model.skeleton;
  if (auto e = s.validate(); !e.empty()) return "skeleton: " + e;
  if (auto e = check_mesh_values(model.mesh, s.bone_count()); !e.empty()) return e;
  if (model.influences.vertex_count() != model.mesh.vertex_count())
    return "influences: " + std::to_string(model.influences.vertex_count()) +
           " vertices, the mesh " + std::to_string(model.mesh.vertex_count());
  // The importer renormalizes every vertex's weights and checks them to 1e-4 (import.cpp).
  if (auto e = model.influences.validate(s.bone_count(), 1e-4); !e.empty())
    return "influences: " + e;
  for (const auto& a : model.animations)
    if (auto e = a.validate(s); !e.empty()) return e;
  return check_infos(model);
}

}  // namespace conform::io
