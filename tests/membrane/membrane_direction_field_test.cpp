// The pre-stress direction field derived from the bones (SkinMaterial::prestress_field): the
// bones' axes from the bind versors, and on the procedural arm the along and around fields
// against the arm's own surface parametrisation (its uvs run around and along the limb), which
// is built independently of the skeleton. On a real model (huesitos.fbx as imported): every
// face gets a unit tangent, and a membrane builds on it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "conform/io/import.hpp"
#include "conform/membrane/model.hpp"
#include "conform/skin/limb_axes.hpp"
#include "conform/skin/procedural_arm.hpp"

namespace conform::membrane {
namespace {

using Field = SkinMaterial::DirectionField;

Eigen::Vector3d face_normal(const mesh::SkinnedMesh& m, const mesh::Face& f) {
  const Eigen::Vector3d x0 = m.rest.col(f[0]), x1 = m.rest.col(f[1]), x2 = m.rest.col(f[2]);
  return (x1 - x0).cross(x2 - x0).normalized();
}

// The 3D gradient on face f of a per-vertex scalar (uv coordinate k).
Eigen::Vector3d uv_gradient(const mesh::SkinnedMesh& m, const mesh::Face& f, int k) {
  const Eigen::Vector3d x0 = m.rest.col(f[0]), e1 = Eigen::Vector3d(m.rest.col(f[1])) - x0,
                        e2 = Eigen::Vector3d(m.rest.col(f[2])) - x0;
  const double d1 = m.uvs(k, f[1]) - m.uvs(k, f[0]), d2 = m.uvs(k, f[2]) - m.uvs(k, f[0]);
  Eigen::Matrix2d g;
  g << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
  const Eigen::Vector2d c = g.ldlt().solve(Eigen::Vector2d(d1, d2));
  return c[0] * e1 + c[1] * e2;
}

TEST(MembraneDirectionField, TheArmsBonesPointFromShoulderToWrist) {
  const skin::Arm arm = skin::make_arm(1);
  const std::vector<Eigen::Vector3d> axes = skin::bone_axes(arm.skeleton);
  ASSERT_EQ(axes.size(), 3u);
  // The arm is built along +z (shoulder at the origin); the wrist's bone, without a child,
  // continues its parent's direction.
  for (const Eigen::Vector3d& a : axes) EXPECT_LT((a - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
}

TEST(MembraneDirectionField, AlongAndAroundFollowTheArmsSurfaceParametrisation) {
  const skin::Arm arm = skin::make_arm(1);
  const mesh::SkinnedMesh& m = arm.mesh;
  const Eigen::Matrix3Xd limb = skin::vertex_limb_axes(m, skin::bone_axes(arm.skeleton));
  SkinMaterial along, around;
  along.prestress_field = Field::along_bones;
  around.prestress_field = Field::around_bones;
  int aligned = 0, counted = 0;
  for (const mesh::Face& f : m.faces) {
    const Eigen::Vector3d n = face_normal(m, f), axis = face_limb_axis(limb, f);
    const Eigen::Vector3d ta = face_prestress_tangent(along, n, axis),
                          tr = face_prestress_tangent(around, n, axis);
    EXPECT_NEAR(ta.norm(), 1, 1e-12);
    EXPECT_NEAR(tr.norm(), 1, 1e-12);
    EXPECT_NEAR(ta.dot(n), 0, 1e-12);
    EXPECT_NEAR(tr.dot(ta), 0, 1e-12);
    // The arm's rings lie at constant z, so the direction across them (the gradient of v, the
    // along-limb uv) is the limb axis's tangent; around is n x along by construction (checked
    // above). Faces of the seam (u wraps from 1 to 0) are left out.
    const double u0 = m.uvs(0, f[0]), u1 = m.uvs(0, f[1]), u2 = m.uvs(0, f[2]);
    if (std::max({u0, u1, u2}) - std::min({u0, u1, u2}) > 0.5) continue;
    const Eigen::Vector3d gu = uv_gradient(m, f, 0), gv = uv_gradient(m, f, 1);
    if (!(gu.norm() > 0 && gv.norm() > 0)) continue;
    ++counted;
    aligned += std::abs(ta.dot(gv.normalized())) > 0.999;
  }
  EXPECT_GT(counted, m.face_count() * 9 / 10);
  EXPECT_GE(aligned, counted * 98 / 100) << aligned << " of " << counted;
}

TEST(MembraneDirectionField, TheBoneFieldsNeedTheLimbAxes) {
  const skin::Arm arm = skin::make_arm(1);
  SkinMaterial m;
  m.prestress_field = Field::around_bones;
  m.prestress = {80e3, 40e3};
  Model model;
  EXPECT_THROW(model.build(arm.mesh.rest, arm.mesh.faces, m), std::invalid_argument);
  const Eigen::Matrix3Xd limb = skin::vertex_limb_axes(arm.mesh, skin::bone_axes(arm.skeleton));
  EXPECT_NO_THROW(model.build(arm.mesh.rest, arm.mesh.faces, m, &limb));
  EXPECT_EQ(model.element_count(), arm.mesh.face_count());
}

TEST(MembraneDirectionField, ARealModelGetsATangentOnEveryFace) {
  const std::filesystem::path path =
      std::filesystem::path(CONFORM_ASSIMP_MODELS) / "FBX/huesitos.fbx";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "assimp-testmodels not installed";
  const io::SkinnedModel model = io::load_model(path.string());
  const mesh::SkinnedMesh& m = model.mesh;
  const Eigen::Matrix3Xd limb = skin::vertex_limb_axes(m, skin::bone_axes(model.skeleton));
  for (const Field field : {Field::along_bones, Field::around_bones}) {
    SkinMaterial material;
    material.prestress_field = field;
    material.prestress = {80e3, 40e3};
    int fallback = 0;
    for (const mesh::Face& f : m.faces) {
      const Eigen::Vector3d n = face_normal(m, f), axis = face_limb_axis(limb, f);
      const Eigen::Vector3d t = face_prestress_tangent(material, n, axis);
      ASSERT_TRUE(t.allFinite());
      EXPECT_NEAR(t.norm(), 1, 1e-12);
      EXPECT_NEAR(t.dot(n), 0, 1e-12);
      const Eigen::Vector3d projected = axis - axis.dot(n) * n;
      fallback += !(projected.norm() > kNormalAxis * axis.norm() && projected.norm() > 0);
    }
    // The limbs' ends (faces whose limb axis is their normal) are few: 8 of 120 here.
    EXPECT_LT(fallback, m.face_count() / 10) << int(field);
    Model membrane;
    EXPECT_NO_THROW(membrane.build(m.rest, m.faces, material, &limb));
  }
}

}  // namespace
}  // namespace conform::membrane
