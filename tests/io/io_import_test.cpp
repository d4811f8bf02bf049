// Import of real rigged models (Debian's assimp-testmodels) and the correctness of the whole
// skinning path against matrix LBS computed independently from assimp's own aiMatrix4x4 node
// and offset matrices, in double, at every key time of every animation.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>

#include "assimp_reference.hpp"
#include "conform/io/import.hpp"
#include "conform/skin/baselines.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;
using M4 = aiMatrix4x4t<double>;
using test::Reference;

const std::string kModels = CONFORM_ASSIMP_MODELS;

struct Case {
  const char* path;
  int bones, animations, vertices;
  int influences = 4;  // the file's largest number per vertex: all are used
  // A non-uniformly scaled mesh node: the importer bakes it, and the file's offsets are not
  // similarities, so the projected reference (similar()) does not apply; the raw one does.
  bool baked = false;
};

class RealModel : public testing::TestWithParam<Case> {};

TEST_P(RealModel, CgaSkinningEqualsAssimpMatrixLbsAtEveryKey) {
  const Case c = GetParam();
  const std::string file = kModels + "/" + c.path;
  io::ImportOptions options;
  options.weld = false;  // vertex by vertex against assimp's; welded: mesh_weld_test.cpp
  const io::SkinnedModel model = io::import_model(file, options);
  EXPECT_EQ(model.influences.max_per_vertex(), c.influences);
  Reference ref(file);
  ASSERT_NE(ref.scene, nullptr);
  EXPECT_EQ(model.skeleton.bone_count(), c.bones);
  EXPECT_EQ(static_cast<int>(model.animations.size()), c.animations);
  EXPECT_EQ(model.mesh.vertex_count(), c.vertices);

  // Bind pose first. `current` is the skinned bind pose in world space, with the shared
  // mesh's 4 influences; the skinner uses all of the file's.
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences, c.influences);
  skinner.skin(skin::Pose::rest(model.skeleton), skin::SkinMode::cga);
  Eigen::Matrix3Xd rest_pose;
  skinner.write(rest_pose);
  const Eigen::Matrix3Xd bind = ref.lbs(-1, 0, true);
  const double diag = (bind.rowwise().maxCoeff() - bind.rowwise().minCoeff()).norm();
  ASSERT_GT(diag, 0);
  const double tol = 1e-9 * diag;
  if (!c.baked) {
    EXPECT_LT((rest_pose - bind).colwise().norm().maxCoeff(), tol);
  }
  if (c.influences <= 4 && !c.baked) {
    EXPECT_LT((model.mesh.current - bind).colwise().norm().maxCoeff(), tol);
  }

  // Against the raw float matrices of the file: equal to float precision.
  ref.project = false;
  const Eigen::Matrix3Xd raw_bind = ref.lbs(-1, 0, true);
  const double raw = (rest_pose - raw_bind).colwise().norm().maxCoeff() / diag;
  EXPECT_LT(raw, 1e-6);
  bool warned = false;
  for (const auto& w : model.warnings)
    warned = warned || w.find("non-uniform") != std::string::npos;
  EXPECT_FALSE(warned);  // every transform of these files is represented exactly
  ref.project = true;

  skin::Pose pose;
  int checked = 0;
  double worst_lbs = 0, worst_dq = 0, moved = 0, worst_raw = 0;
  for (int a = 0; a < static_cast<int>(model.animations.size()); ++a) {
    const auto& anim = model.animations[static_cast<std::size_t>(a)];
    std::vector<double> times = anim.key_times();
    // and some times between keys
    for (std::size_t i = 0; i + 1 < anim.key_times().size(); i += 3)
      times.push_back(0.37 * anim.key_times()[i] + 0.63 * anim.key_times()[i + 1]);
    for (const skin::Blend blend : {skin::Blend::log, skin::Blend::linear}) {
      const bool log = blend == skin::Blend::log;
      for (const double t : times) {
        anim.sample(model.skeleton, t, blend, pose);
        Eigen::Matrix3Xd dq;
        const Eigen::Matrix3Xd expected = ref.lbs(a, t, log, &dq);
        Eigen::Matrix3Xd got;
        skinner.skin(pose, skin::SkinMode::cga);
        skinner.write(got);
        worst_lbs = std::max(worst_lbs, (got - expected).colwise().norm().maxCoeff());
        skinner.skin(pose, skin::SkinMode::versor);
        skinner.write(got);
        worst_dq = std::max(worst_dq, (got - dq).colwise().norm().maxCoeff());
        moved = std::max(moved, (expected - bind).colwise().norm().maxCoeff());
        ref.project = false;
        skinner.skin(pose, skin::SkinMode::cga);
        skinner.write(got);
        worst_raw = std::max(worst_raw, (got - ref.lbs(a, t, log)).colwise().norm().maxCoeff());
        ref.project = true;
        ++checked;
      }
    }
  }
  RecordProperty("worst_lbs_over_diag", std::to_string(worst_lbs / diag));
  std::printf(
      "%s: %d poses, diag %.4g, worst |CGA − LBS| / diag = %.3g, |versor − DQ| / diag = %.3g; "
      "vs unprojected float matrices: bind %.3g, poses %.3g\n",
      c.path, checked, diag, worst_lbs / diag, worst_dq / diag, raw, worst_raw / diag);
  EXPECT_LT(worst_raw, 1e-6 * diag);
  if (!c.baked) {
    EXPECT_LT(worst_lbs, tol);
    EXPECT_LT(worst_dq, tol);
  }
  if (c.animations > 0) {
    EXPECT_GT(checked, 0);
    EXPECT_GT(moved, 1e-3 * diag);  // the animation really moves the mesh
  }
}

INSTANTIATE_TEST_SUITE_P(
    AssimpTestModels, RealModel,
    testing::Values(Case{"glTF2/simple_skin/simple_skin.gltf", 2, 1, 10, 2},
                    Case{"FBX/huesitos.fbx", 9, 1, 128}, Case{"X/anim_test.x", 4, 1, 485},
                    // weights summing to 0.94–1.38 (normalized), up to 6 per vertex, and
                    // a non-uniformly scaled mesh node (121 × 100 × 100): baked, exact
                    Case{"FBX/animation_with_skeleton.fbx", 14, 1, 2464, 6, true}),
    [](const auto& info) {
      std::string n = info.param.path;
      n = n.substr(n.rfind('/') + 1);
      for (auto& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(IoImport, ModelStructure) {
  const auto m = io::import_model(kModels + "/FBX/huesitos.fbx");
  EXPECT_EQ(m.influences.max_per_vertex(), 4);
  EXPECT_EQ(m.meshes.size(), 1u);
  EXPECT_EQ(m.skeleton.validate(), "");
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].ticks_per_second, 25);
  EXPECT_NEAR(m.animations[0].duration(), 39.0 / 25, 1e-12);
  EXPECT_EQ(m.find_animation("Armature|Action"), 0);
  EXPECT_EQ(m.find_animation("0"), 0);
  EXPECT_EQ(m.find_animation("1"), -1);
  EXPECT_GE(m.skeleton.find_joint("Bone.008"), 0);
  // The mesh keeps the 4 largest influences; weights sorted and summing to 1.
  for (int v = 0; v < m.mesh.vertex_count(); ++v) {
    EXPECT_NEAR(m.mesh.weights.col(v).sum(), 1.0, 1e-12);
    for (int k = 0; k + 1 < 4; ++k) EXPECT_GE(m.mesh.weights(k, v), m.mesh.weights(k + 1, v));
  }
  // Warned about the unnormalized weights of the file (sums 0.948 … 1).
  bool warned = false;
  for (const auto& w : m.warnings) warned = warned || w.find("renormalized") != std::string::npos;
  EXPECT_TRUE(warned);

  const auto x = io::import_model(kModels + "/X/anim_test.x");
  EXPECT_EQ(x.animations[0].ticks_per_second, 24);
  EXPECT_GE(x.skeleton.find_joint("joint3"), 0);  // bone without a node: a joint of its own
}

// A model without bones is one rigid bone per mesh node and follows its node.
TEST(IoImport, MeshWithoutBonesIsOneRigidBone) {
  const std::string file = kModels + "/OBJ/box.obj";
  io::ImportOptions unwelded;
  unwelded.weld = false;  // vertex by vertex against assimp's
  const auto m = io::import_model(file, unwelded);
  EXPECT_EQ(m.animations.size(), 0u);
  EXPECT_GE(m.skeleton.bone_count(), 1);
  EXPECT_EQ(m.influences.max_per_vertex(), 1);
  Reference ref(file);
  const Eigen::Matrix3Xd bind = ref.lbs(-1, 0, true);
  EXPECT_LT((m.mesh.current - bind).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(IoImport, ArmSpecs) {
  const auto a = io::load_model("arm");
  EXPECT_EQ(a.mesh.vertex_count(), 2562);
  EXPECT_EQ(a.source, "arm:1");
  EXPECT_EQ(io::load_model("arm:2").mesh.face_count(), 4 * 5120);
  for (const char* bad : {"arm:", "arm:0", "arm:x", "arm:2x", "arm:-1"}) {
    try {
      io::load_model(bad);
      ADD_FAILURE() << bad;
    } catch (const io::ImportError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos);
    }
  }
}

// A file that gives no ticks per second (assimp reports 0) plays at 25 ticks/s; the animated
// bone moves its vertices. Written at test time: a one-triangle X file with one bone.
TEST(IoImport, ZeroTicksPerSecondMeans25) {
  const std::string x = R"(xof 0303txt 0032
Frame Root {
  FrameTransformMatrix {
    1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
  }
  Frame Bone1 {
    FrameTransformMatrix {
      1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
    }
  }
  Mesh Tri {
    3;
    0.0;0.0;0.0;,
    1.0;0.0;0.0;,
    0.0;1.0;0.0;;
    1;
    3;0,1,2;;
    XSkinMeshHeader {
      1;
      1;
      1;
    }
    SkinWeights {
      "Bone1";
      3;
      0,
      1,
      2;
      1.000000,
      1.000000,
      1.000000;
      1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
    }
  }
}
AnimationSet Wave {
  Animation {
    { Bone1 }
    AnimationKey {
      2;
      3;
      0;3;0.0,0.0,0.0;;,
      10;3;1.0,0.0,0.0;;,
      50;3;1.0,2.0,0.0;;;
    }
  }
}
)";
  const std::string file = testing::TempDir() + "conform_zero_tps.x";
  { std::ofstream(file) << x; }
  const auto m = io::import_model(file);
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].ticks_per_second, 25.0);
  EXPECT_DOUBLE_EQ(m.animations[0].duration(), 2.0);  // 50 ticks
  skin::Pose pose;
  m.animations[0].sample(m.skeleton, 0.4, skin::Blend::log, pose);  // tick 10: (1, 0, 0)
  skin::Skinner<double> s(m.skeleton, m.mesh.rest, m.influences);
  s.skin(pose, skin::SkinMode::cga);
  Eigen::Matrix3Xd out;
  s.write(out);
  EXPECT_LT((out.colwise() - Eigen::Vector3d(1, 0, 0) - m.mesh.current).cwiseAbs().maxCoeff(),
            1e-12);
  m.animations[0].sample(m.skeleton, 1.2, skin::Blend::linear, pose);  // tick 30: (1, 1, 0)
  s.skin(pose, skin::SkinMode::cga);
  s.write(out);
  EXPECT_LT((out.colwise() - Eigen::Vector3d(1, 1, 0) - m.mesh.current).cwiseAbs().maxCoeff(),
            1e-12);
}

}  // namespace
