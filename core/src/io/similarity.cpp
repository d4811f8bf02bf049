#include "similarity.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace conform::io::detail {
namespace {
constexpr double kSimilarityTolerance = 1e-5;  // float matrices are orthonormal to ~1e-7
}

std::optional<NearestVersor> nearest_versor(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) return std::nullopt;
  if (std::abs(m(3, 0)) > 1e-6 || std::abs(m(3, 1)) > 1e-6 || std::abs(m(3, 2)) > 1e-6 ||
      std::abs(m(3, 3) - 1) > 1e-6)
    return std::nullopt;
  const Eigen::Matrix3d a = m.topLeftCorner<3, 3>();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  if (!(sigma.minCoeff() > 1e-12 * std::max(1.0, sigma.maxCoeff()))) return std::nullopt;
  Eigen::Matrix3d u = svd.matrixU();
  NearestVersor d;
  if ((u * svd.matrixV().transpose()).determinant() < 0) {
    u.col(2) = -u.col(2);  // keep the proper rotation nearest to the mirror
    d.mirror = true;
  }
  const Eigen::Matrix3d r = u * svd.matrixV().transpose();
  const double s = sigma.mean();
  d.exact = !d.mirror && (sigma.maxCoeff() - sigma.minCoeff()) <= kSimilarityTolerance * s;
  d.versor =
      skin::Versor::from_trs(m.topRightCorner<3, 1>(), Eigen::Quaterniond(r).normalized(), s);
  return d;
}

bool is_proper_similarity(const Eigen::Matrix4d& m) {
  const auto d = nearest_versor(m);
  return d && d->exact;
}

Eigen::Matrix4d reflected(Eigen::Matrix4d m, bool left, bool right) {
  if (left) m.row(2) = -m.row(2);
  if (right) m.col(2) = -m.col(2);
  return m;
}

Eigen::Quaterniond reflected(const Eigen::Quaterniond& q) {
  return Eigen::Quaterniond(q.w(), -q.x(), -q.y(), q.z());
}

}  // namespace conform::io::detail
