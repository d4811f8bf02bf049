#include "kinds/body_fields.hpp"

#include <algorithm>

#include "conform/skin/pose.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/membrane_stress.hpp"

namespace conform::scenes {

namespace {

// Every vertex where the bind pose puts it (the rest pose skinned, placed in the world as the
// body's targets are): the reference of the displacement. An imported model's rest positions
// need not be at the bind pose's scale; its skinned rest pose is.
Eigen::Matrix3Xd bind_positions(const bullet::SkinnedSoftBody& body) {
  const mesh::SkinnedMesh& mesh = body.mesh();
  skin::Skinner<double> skinner(body.skeleton(), mesh.rest,
                                skin::Influences<double>::from_mesh(mesh));
  skinner.set_threads(1);
  skinner.skin(skin::Pose::rest(body.skeleton()), skin::SkinMode::cga);
  Eigen::Matrix3Xd bind(3, mesh.vertex_count());
  skinner.write(bind);
  return body.world_transform() * bind;
}

// Each vertex's piece as its index among the body's live pieces (-1: none).
std::vector<std::int32_t> piece_indices(const bullet::SkinnedSoftBody& body) {
  const std::vector<bullet::PieceId> ids = body.piece_ids();
  std::vector<std::int32_t> piece;
  piece.reserve(std::size_t(body.vertex_count()));
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    const auto it = std::find(ids.begin(), ids.end(), body.piece_of(v));
    piece.push_back(it == ids.end() ? -1 : std::int32_t(it - ids.begin()));
  }
  return piece;
}

}  // namespace

VertexFields body_fields(const bullet::SkinnedSoftBody& body, const Lips* lips) {
  const mesh::SkinnedMesh& mesh = body.mesh();
  const std::int32_t n = mesh.vertex_count();
  VertexFields f;
  f.positions = mesh.current;
  f.displacement = f.positions - bind_positions(body);
  f.velocity.resize(3, n);
  for (std::int32_t v = 0; v < n; ++v) f.velocity.col(v) = body.velocity(v);
  f.faces = mesh.faces;
  for (std::int32_t i = 0; i < mesh.face_count(); ++i) f.tags.push_back(mesh.face_tag(i));
  f.stretch = edge_stretch(mesh);
  if (lips)
    f.gap = gap_width(f.positions, *lips);
  else
    f.omitted.push_back("gap: the scene has no tear, so no lips to measure across");
  if (body.material().model == bullet::MaterialModel::membrane)
    f.principal_stress = vertex_principal_stresses(mesh, body.material().skin, body.skeleton());
  else
    f.omitted.push_back(
        "principal_stress: the body runs Bullet's links (material.model = "
        "bullet_links), not the membrane");
  f.piece = piece_indices(body);
  return f;
}

}  // namespace conform::scenes
