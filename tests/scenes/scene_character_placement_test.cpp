// Where the character scene's edits land on a user's own model: by default on a limb found
// from the skeleton and tried on the skinned model, held by the skin at the moment of the edit.
// The primitives are checked against independent oracles (brute-force sampling, the procedural
// arm's known shape); the scene against real models of Debian's assimp-testmodels as imported.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <random>
#include <string>

#include "conform/skin/procedural_arm.hpp"
#include "conform_run.hpp"
#include "kinds/edit_placement.hpp"
#include "kinds/surface_point.hpp"

namespace {

namespace fs = std::filesystem;
using conform::scenes::BindPose;
using Json = nlohmann::json;
using Vec3 = Eigen::Vector3d;

const std::string kModels = "/usr/share/assimp/models/";

TEST(SurfacePoint, IsTheNearestPointOfTheFacesBySampling) {
  // Random triangles and queries: no sample of any face is nearer than the point found, and
  // the point found is no farther than the nearest sample by more than the sampling step.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix3Xd x(3, 12);
  for (int v = 0; v < 12; ++v) x.col(v) = Vec3(u(rng), u(rng), u(rng));
  const std::vector<conform::mesh::Face> faces{{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {9, 10, 11}};
  const std::vector<std::int32_t> all{0, 1, 2, 3};
  const int n = 200;
  for (int q = 0; q < 50; ++q) {
    const Vec3 query = 2 * Vec3(u(rng), u(rng), u(rng));
    const conform::scenes::SurfacePoint s =
        conform::scenes::nearest_surface_point(x, faces, all, query);
    double sampled = 1e300;
    for (const auto& f : faces)
      for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j) {
          const Vec3 p = x.col(f[0]) + (x.col(f[1]) - x.col(f[0])) * (double(i) / n) +
                         (x.col(f[2]) - x.col(f[0])) * (double(j) / n);
          sampled = std::min(sampled, (p - query).norm());
        }
    EXPECT_LE(s.distance, sampled + 1e-12) << q;
    EXPECT_GE(s.distance, sampled - 0.03) << q;  // the samples' spacing, at most ~0.02
    EXPECT_NEAR((s.point - query).norm(), s.distance, 1e-12);
    EXPECT_GE(s.normal.dot(query - s.point), -1e-12) << "the normal faces the query";
  }
}

TEST(Limb, TheArmsForearmRunsAlongItsAxisAwayFromTheElbow) {
  // The procedural arm points along +z, the elbow at z = 0.30 m, the finger tips at 0.63 m.
  const conform::skin::Arm arm = conform::skin::make_arm(1);
  const BindPose bind(arm.mesh);
  const conform::scenes::Limb forearm = conform::scenes::limb_of(bind, arm.skeleton, 1, "test");
  EXPECT_GT(forearm.axis.z(), std::cos(2 * M_PI / 180)) << forearm.axis.transpose();
  EXPECT_NEAR(forearm.at(0).z(), 0.30, 0.05);  // its root end at the elbow (within the blend)
  EXPECT_NEAR(forearm.at(1).z(), 0.63, 0.01);  // its far end at the finger tips
  EXPECT_NEAR(forearm.side.dot(forearm.axis), 0, 1e-9);
  EXPECT_GT(forearm.radius, 0.01);
  EXPECT_LT(forearm.radius, 0.06);
  EXPECT_FALSE(forearm.flat);
  // The whole arm is no limb of itself (it holds every vertex); the forearm and the hand are.
  const std::vector<std::int32_t> candidates = conform::scenes::limb_candidates(bind, arm.skeleton);
  EXPECT_EQ(std::count(candidates.begin(), candidates.end(), 0), 0);
  EXPECT_EQ(std::count(candidates.begin(), candidates.end(), 1), 1);
}

Json run_model(const std::string& file, const std::string& tag, const std::string& extra = "") {
  const conform::test::CommandRun r = conform::test::run_conform_scene(
      "character", "--no-render --set outputs.plots=false --set model.file=" + file + extra, tag);
  EXPECT_EQ(r.rc, 0) << r.log;
  return r.summary.is_object() ? r.summary["metrics"] : Json();
}

// The character scene run with `args` fails, and its message names each of `names`.
void expect_refused_naming(const std::string& args, const std::string& tag,
                           std::initializer_list<const char*> names) {
  const conform::test::CommandRun bad = conform::test::run_conform_scene("character", args, tag);
  EXPECT_NE(bad.rc, 0);
  for (const char* name : names) EXPECT_NE(bad.log.find(name), std::string::npos) << bad.log;
}

TEST(CharacterPlacement, TheThreeEditsLandOnRealModelsWithTheDefaults) {
  // Each model as imported, the membrane and every placement at its defaults.
  struct Case {
    std::string file;
    bool closed;            // a closed limb: the cut is capped (simple_skin is an open strip)
    double tear_extending;  // the fraction of the tear's later samples that extend it, at least
  };
  const Case cases[] = {{"FBX/huesitos.fbx", true, 0.6},
                        {"FBX/animation_with_skeleton.fbx", true, 0.8},
                        {"X/BCN_Epileptic.X", true, 0.9},
                        {"X/Testwuson.X", true, 0.8},
                        {"X/anim_test.x", true, 0.8},
                        {"SMD/WusonSMD.smd", true, 0.7},
                        {"glTF2/simple_skin/simple_skin.gltf", false, 0.8}};
  for (const Case& c : cases) {
    if (!fs::exists(kModels + c.file)) GTEST_SKIP() << "no assimp-testmodels";
    const Json m = run_model(kModels + c.file, "placement_" + fs::path(c.file).stem().string());
    ASSERT_TRUE(m.is_object()) << c.file;
    EXPECT_EQ(m["cut"]["status"], "cut") << c.file << " " << m["cut"];
    EXPECT_EQ(m["drill"]["status"], "drilled") << c.file << " " << m["drill"];
    EXPECT_GE(m["drill"]["holes"].get<int>(), 1) << c.file;
    EXPECT_EQ(m["tear"]["placement"], "limb") << c.file;
    EXPECT_GE(m["tear"]["extended_fraction"].get<double>(), c.tear_extending)
        << c.file << " " << m["tear"];
    // One limb for the three edits, and the cut bounded to its section there.
    EXPECT_FALSE(m["cut"]["limb"].get<std::string>().empty()) << c.file;
    EXPECT_EQ(m["cut"]["limb"], m["tear"]["limb"]) << c.file;
    EXPECT_EQ(m["cut"]["limb"], m["drill"]["limb"]) << c.file;
    EXPECT_LE(m["cut"]["kept_sections"].get<int>(), 1) << c.file << " " << m["cut"];
    if (c.closed) {
      EXPECT_EQ(m["cut"]["loops"].get<int>(), 1) << c.file << " " << m["cut"];
      EXPECT_EQ(m["cut"]["capped_loops"].get<int>(), 1) << c.file << " " << m["cut"];
    }
  }
}

TEST(CharacterPlacement, ANamedBoneAimsEveryEditAtItsLimb) {
  const std::string file = kModels + "FBX/huesitos.fbx";
  if (!fs::exists(file)) GTEST_SKIP() << "no assimp-testmodels";
  const Json m = run_model(file, "placement_bone",
                           " --set cut.bone=Bone.003 --set tear.bone=Bone.003 "
                           "--set drill.bone=Bone.003 --set tear.side=inner");
  ASSERT_TRUE(m.is_object());
  for (const char* edit : {"cut", "tear", "drill"}) EXPECT_EQ(m[edit]["limb"], "Bone.003") << edit;
  expect_refused_naming(
      "--steps 2 --set cut.at=0 --set tear.enabled=false --set drill.enabled=false "
      "--set cut.bone=Femur",
      "placement_bad_bone", {"cut.bone", "Femur"});
}

TEST(CharacterPlacement, TheBoxsKeysNeedTheirPoint) {
  // A box key without its point is refused by name; with the point the edit is in the box.
  expect_refused_naming("--steps 2 --set cut.normal=[0,1,0]", "placement_box_bad",
                        {"cut.normal", "cut.point"});
  const std::string file = kModels + "FBX/huesitos.fbx";
  if (!fs::exists(file)) GTEST_SKIP() << "no assimp-testmodels";
  const Json m = run_model(file, "placement_box",
                           " --set tear.enabled=false --set drill.enabled=false "
                           "--set cut.point=[0.68,0.39,0.305] --set cut.normal=[1,0,-0.625]");
  ASSERT_TRUE(m.is_object());
  EXPECT_TRUE(m["cut"].contains("seed")) << m["cut"];
  EXPECT_FALSE(m["cut"].contains("limb")) << m["cut"];
}

}  // namespace
