// The principal pre-stress direction lies in every face's plane and depends on the axis and
// the face's normal only: never on which edge the triangle lists first.
#include <gtest/gtest.h>

#include <cmath>

#include "conform/membrane/model.hpp"

namespace conform::membrane {
namespace {

TEST(MembranePrestressAxis, TheAxisIsProjectedOntoTheFacesPlane) {
  const Eigen::Vector3d n = Eigen::Vector3d(0, 1, 1).normalized();
  const Eigen::Vector3d t = prestress_tangent(Eigen::Vector3d(0, 0, 1), n);
  EXPECT_NEAR(t.dot(n), 0, 1e-15);
  EXPECT_NEAR(t.norm(), 1, 1e-15);
  EXPECT_LT((t - Eigen::Vector3d(0, -1, 1).normalized()).norm(), 1e-15);
  EXPECT_LT((prestress_tangent(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::UnitZ()) -
             Eigen::Vector3d::UnitX())
                .norm(),
            1e-15);
}

TEST(MembranePrestressAxis, AnAxisNormalToTheFaceTakesTheLeastAlignedWorldAxis) {
  // z on a face of normal +-z: x (the first of the two world axes normal to z).
  for (const double sign : {1.0, -1.0})
    EXPECT_LT((prestress_tangent(Eigen::Vector3d::UnitZ(), sign * Eigen::Vector3d::UnitZ()) -
               Eigen::Vector3d::UnitX())
                  .norm(),
              1e-15);
  // x on a face of normal x: y.
  EXPECT_LT((prestress_tangent(Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX()) -
             Eigen::Vector3d::UnitY())
                .norm(),
            1e-15);
}

// The world-space pre-stress R S0 R^T of the model's only element (R = [e1 e2], its frame).
Eigen::Matrix3d world_prestress(const Eigen::Matrix3Xd& rest, const mesh::Face& face,
                                const SkinMaterial& material) {
  Model model;
  const mesh::Face faces[] = {face};
  model.build(rest, faces, material);
  const Eigen::Vector3d x0 = rest.col(face[0]), x1 = rest.col(face[1]), x2 = rest.col(face[2]);
  const Eigen::Vector3d e1 = (x1 - x0).normalized(), n = (x1 - x0).cross(x2 - x0).normalized();
  Eigen::Matrix<double, 3, 2> r;
  r << e1, n.cross(e1);
  return r * model.elements()[0].s0 * r.transpose();
}

TEST(MembranePrestressAxis, NoFaceTakesItsFirstEdge) {
  Eigen::Matrix3Xd rest(3, 3);
  rest << 0, 1, 0.3, 0, 0.2, 1, 0, 0, 0;  // a triangle in z = 0, no edge along x or y
  SkinMaterial material;
  material.prestress = {2000, 1000};
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0)}) {
    material.prestress_axis = axis;
    Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
    expected(0, 0) = 2000;  // both axes give x in this plane
    expected(1, 1) = 1000;
    for (const mesh::Face& face : {mesh::Face{0, 1, 2}, mesh::Face{1, 2, 0}, mesh::Face{2, 0, 1}})
      EXPECT_LT((world_prestress(rest, face, material) - expected).norm(), 1e-9)
          << "axis " << axis.transpose() << " face " << face[0] << face[1] << face[2];
  }
}

}  // namespace
}  // namespace conform::membrane
