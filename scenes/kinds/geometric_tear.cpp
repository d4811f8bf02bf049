#include "kinds/geometric_tear.hpp"

namespace conform::scenes {

GeometricTear::GeometricTear(mesh::SkinnedMesh mesh, const mesh::TearOptions& options)
    : mesh_(std::move(mesh)), adjacency_(mesh_), tear_(mesh_, adjacency_, options) {}

void GeometricTear::open(double amount) {
  tear_.open(amount);
  amount_ = amount;
}

void GeometricTear::repose(const skin::Skeleton& skeleton, const skin::Pose& pose,
                           const Eigen::Isometry3d& world) {
  const std::int32_t n = mesh_.vertex_count();
  if (!skinner_) {
    skinner_ = std::make_unique<skin::Skinner<double>>(skeleton, mesh_.rest,
                                                       skin::Influences<double>::from_mesh(mesh_));
    skinner_->set_threads(1);
  } else if (skinned_vertices_ != n) {  // the tear added vertices
    skinner_->set_points(mesh_.rest, skin::Influences<double>::from_mesh(mesh_));
  }
  skinned_vertices_ = n;
  skinner_->skin(pose, skin::SkinMode::cga);
  Eigen::Matrix3Xd posed;
  skinner_->write(posed);
  for (std::int32_t v = 0; v < n; ++v) mesh_.current.col(v) = world * Eigen::Vector3d(posed.col(v));
  if (amount_) tear_.open(*amount_);
}

Profile GeometricTear::profile() const {
  if (tear_.path_length() < 2) return {};
  return measure_profile(
      tear_.left_border(), tear_.right_border(),
      [this](std::int32_t v) { return Eigen::Vector3d(mesh_.current.col(v)); },
      [this](std::int32_t v) { return Eigen::Vector3d(mesh_.rest.col(v)); });
}

}  // namespace conform::scenes
