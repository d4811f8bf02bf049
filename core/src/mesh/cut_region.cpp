#include "conform/mesh/cut_region.hpp"

#include <cmath>
#include <sstream>

namespace conform::mesh {

CutRegion CutRegion::sphere(const Eigen::Vector3d& center, double radius, Keep keep) {
  CutRegion r;
  r.shape = Shape::sphere, r.keep = keep, r.center = center, r.radius = radius;
  return r;
}

CutRegion CutRegion::box(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents,
                         const Eigen::Matrix3d& axes, Keep keep) {
  CutRegion r;
  r.shape = Shape::box, r.keep = keep, r.center = center, r.half_extents = half_extents;
  r.axes = axes;
  return r;
}

CutRegion CutRegion::seed(const Eigen::Vector3d& point) {
  CutRegion r;
  r.shape = Shape::seed, r.center = point;
  return r;
}

std::string CutRegion::validate() const {
  std::ostringstream os;
  if (shape == Shape::everywhere) return {};
  if (!center.allFinite()) {
    os << "cut region: center = (" << center.transpose() << ") must be finite";
  } else if (shape == Shape::sphere && !(std::isfinite(radius) && radius > 0)) {
    os << "cut region: radius = " << radius << " must be finite and > 0";
  } else if (shape == Shape::box) {
    if (!(half_extents.allFinite() && half_extents.minCoeff() > 0))
      os << "cut region: half_extents = (" << half_extents.transpose()
         << ") must be finite and > 0";
    else if (!axes.allFinite() ||
             !((axes.transpose() * axes - Eigen::Matrix3d::Identity()).norm() < 1e-9))
      os << "cut region: axes must be orthonormal columns (|AᵀA − I| = "
         << (axes.transpose() * axes - Eigen::Matrix3d::Identity()).norm() << ")";
  }
  return os.str();
}

bool CutRegion::contains(const Eigen::Vector3d& x) const {
  switch (shape) {
    case Shape::sphere:
      return (x - center).squaredNorm() <= radius * radius;
    case Shape::box: {
      const Eigen::Vector3d local = axes.transpose() * (x - center);
      return (local.cwiseAbs().array() <= half_extents.array()).all();
    }
    case Shape::everywhere:
    case Shape::seed:
      break;
  }
  return true;
}

}  // namespace conform::mesh
