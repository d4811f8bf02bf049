// The character scene on a user's own model: its units (every figure in metres whatever the
// file's units), its up axis, a model without animation (its bind pose plays) and a cut
// bounded to the aimed limb. Each run is the `conform` command on a small model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "conform_run.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const std::string kModels = "/usr/share/assimp/models/";
// A short run stops before the edits, which must then be off.
const std::string kNoEdits =
    " --set cut.enabled=false --set tear.enabled=false --set drill.enabled=false ";

using Outcome = conform::test::CommandRun;

// `conform run character ARGS` into a fresh folder.
Outcome run(const std::string& args, const std::string& tag) {
  return conform::test::run_conform_scene(
      "character", "--no-render --set outputs.plots=false " + args, "character_" + tag);
}

// simple_skin.gltf with its scene under a node scaled by `scale`: the file's coordinates (its
// mesh, skeleton and animation as skinned) `scale` times larger.
fs::path scaled_gltf(double scale) {
  std::ifstream in(kModels + "glTF2/simple_skin/simple_skin.gltf");
  Json g = Json::parse(in);
  Json& nodes = g["nodes"];
  nodes.push_back({{"scale", {scale, scale, scale}}, {"children", g["scenes"][0]["nodes"]}});
  g["scenes"][0]["nodes"] = {nodes.size() - 1};
  const fs::path out =
      fs::path(testing::TempDir()) / ("simple_skin_x" + std::to_string(int(scale)) + ".gltf");
  std::ofstream(out) << g.dump();
  return out;
}

// Every number of `a` against the same one of `b`: relative 1e-6 (absolute 1e-12 near 0).
void expect_same_numbers(const Json& a, const Json& b, const std::string& path) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_LE(std::abs(x - y), 1e-6 * std::max(std::abs(x), std::abs(y)) + 1e-12)
        << path << ": " << x << " against " << y;
  } else if (a.is_structured() && b.is_structured()) {
    ASSERT_EQ(a.size(), b.size()) << path;
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (a.is_object()) {
        ASSERT_TRUE(b.contains(it.key())) << path << "." << it.key();
        expect_same_numbers(it.value(), b[it.key()], path + "." + it.key());
      }
    }
    if (a.is_array())
      for (std::size_t i = 0; i < a.size(); ++i)
        expect_same_numbers(a[i], b[i], path + "[" + std::to_string(i) + "]");
  }
}

TEST(CharacterUnits, AModelInMillimetresRuns) {
  // The collision margin (m) was converted to model units and then checked in metres: 5 mm at
  // 1000 units per metre was refused as 5 m.
  if (!fs::exists(kModels + "FBX/huesitos.fbx")) GTEST_SKIP() << "no assimp-testmodels";
  const Outcome r = run("--steps 3 --set model.units_per_metre=1000" + kNoEdits, "mm");
  EXPECT_EQ(r.rc, 0) << r.log;
}

TEST(CharacterUnits, TheUnitTheFileStatesIsTheDefault) {
  // FBX files state their unit (UnitScaleFactor, centimetres per unit): huesitos.fbx's is 1 cm.
  // An .X file states none: metres, assumed (glTF's unit and Bullet's; BCN_Epileptic.X is a
  // 1.8 m human in it), and the summary says it is assumed.
  if (!fs::exists(kModels + "FBX/huesitos.fbx")) GTEST_SKIP() << "no assimp-testmodels";
  const Outcome fbx = run("--steps 2" + kNoEdits, "units_fbx");
  ASSERT_EQ(fbx.rc, 0) << fbx.log;
  EXPECT_EQ(fbx.summary["metrics"]["units_per_metre"].get<double>(), 100);
  EXPECT_NE(
      fbx.summary["metrics"]["units_per_metre_from"].get<std::string>().find("UnitScaleFactor"),
      std::string::npos);
  const Outcome x =
      run("--steps 2" + kNoEdits + "--set model.file=" + kModels + "X/anim_test.x", "units_x");
  ASSERT_EQ(x.rc, 0) << x.log;
  EXPECT_EQ(x.summary["metrics"]["units_per_metre"].get<double>(), 1);
  EXPECT_NE(x.summary["metrics"]["units_per_metre_from"].get<std::string>().find("assumed"),
            std::string::npos);
  const Outcome set = run("--steps 2" + kNoEdits + "--set model.units_per_metre=250", "units_set");
  ASSERT_EQ(set.rc, 0) << set.log;
  EXPECT_EQ(set.summary["metrics"]["units_per_metre"].get<double>(), 250);
}

TEST(CharacterUnits, ScaledCopiesGiveTheSameMetresAtTheirUnits) {
  if (!fs::exists(kModels + "glTF2/simple_skin/simple_skin.gltf"))
    GTEST_SKIP() << "no assimp-testmodels";
  Json reference;
  for (const double scale : {1.0, 100.0, 1000.0}) {
    const std::string units = std::to_string(int(scale));
    const Outcome r = run(
        "--set model.file=" + scaled_gltf(scale).string() + " --set model.units_per_metre=" + units,
        "units_" + units);
    ASSERT_EQ(r.rc, 0) << r.log;
    Json m = r.summary["metrics"];
    m.erase("model");
    m.erase("units_per_metre");  // the one figure in file units
    EXPECT_GT(m["secondary_motion_max_m"].get<double>(), 0);
    if (reference.is_null())
      reference = m;
    else
      expect_same_numbers(reference, m, "units_per_metre=" + units);
  }
}

TEST(CharacterUpAxis, AZUpModelStandsOnItsFeetAlongY) {
  // WusonSMD.smd stands Z up: its feet at z = 0, its height 1.52 units along z (its arms span
  // 3.24 along y, so its box is not tallest along its up axis). Turned Y up, the file's z
  // extent is the body's y extent, from 0 upward; left as it is, it lies along z.
  const std::string file = kModels + "SMD/WusonSMD.smd";
  if (!fs::exists(file)) GTEST_SKIP() << "no assimp-testmodels";
  const std::string args =
      "--steps 2" + kNoEdits + "--set model.units_per_metre=1 " + "--set model.file=" + file;
  const Outcome z = run(args + " --set model.up=z", "up_z");
  ASSERT_EQ(z.rc, 0) << z.log;
  const Json& mz = z.summary["metrics"];
  EXPECT_NEAR(mz["bind_pose_size_m"][1].get<double>(), 1.515817, 1e-5) << mz;
  EXPECT_NEAR(mz["bind_pose_lo_m"][1].get<double>(), -0.000566, 1e-5) << mz;
  EXPECT_NEAR(mz["bind_pose_size_m"][2].get<double>(), 3.244484, 1e-5) << mz;
  const Outcome y = run(args, "up_y");
  ASSERT_EQ(y.rc, 0) << y.log;
  const Json& my = y.summary["metrics"];
  EXPECT_NEAR(my["bind_pose_size_m"][1].get<double>(), 3.244484, 1e-5) << my;
  EXPECT_NEAR(my["bind_pose_lo_m"][2].get<double>(), -0.000566, 1e-5) << my;
  EXPECT_NEAR(my["bind_pose_size_m"][0].get<double>(), mz["bind_pose_size_m"][0].get<double>(),
              1e-9);
  const Outcome x = run(args + " --set model.up=x", "up_x");
  EXPECT_NE(x.rc, 0);
  EXPECT_NE(x.log.find("model.up"), std::string::npos) << x.log;
  EXPECT_NE(x.log.find("\"x\""), std::string::npos) << x.log;
}

TEST(CharacterBindPose, AModelWithoutAnimationPlaysItsBindPose) {
  const std::string file = kModels + "MD5/SimpleCube.md5mesh";
  if (!fs::exists(file)) GTEST_SKIP() << "no assimp-testmodels";
  const Outcome r = run("--set model.file=" + file, "bind_pose");
  ASSERT_EQ(r.rc, 0) << r.log;
  EXPECT_NE(r.log.find("no animation"), std::string::npos) << r.log;  // the note
  EXPECT_EQ(r.summary["metrics"]["animation"], "none (bind pose)");
  // Asked for: an animated model held in its bind pose.
  const Outcome held = run("--steps 30 --set model.animation=none" + kNoEdits, "bind_pose_asked");
  ASSERT_EQ(held.rc, 0) << held.log;
  EXPECT_EQ(held.summary["metrics"]["animation_duration_s"].get<double>(), 0);
  // An unknown animation is still refused.
  const Outcome bad = run("--steps 2 --set model.animation=walk" + kNoEdits, "bind_pose_bad");
  EXPECT_NE(bad.rc, 0);
  EXPECT_NE(bad.log.find("no animation 'walk'"), std::string::npos) << bad.log;
}

TEST(CharacterCutRegion, AnArmCutSeversTheArmOnly) {
  // A level plane through BCN_Epileptic.X's right forearm (it hangs by the body) also crosses
  // the left arm and the torso: unbounded, it cuts them all (3 loops); bounded to the section
  // nearest the cut's point (the default, cut.region = "nearest"), one loop, around the arm.
  const std::string file = kModels + "X/BCN_Epileptic.X";
  if (!fs::exists(file)) GTEST_SKIP() << "no assimp-testmodels";
  const std::string args =
      "--set duration=0.35 --set tear.enabled=false --set material.model=bullet_links "
      "--set drill.enabled=false --set model.file=" +
      file + " --set cut.point=[0.05,0.65,0.5] --set cut.normal=[0,1,0]";
  const Outcome bounded = run(args, "region_nearest");
  ASSERT_EQ(bounded.rc, 0) << bounded.log;
  const Json& cut = bounded.summary["metrics"]["cut"];
  EXPECT_EQ(cut["region"], "nearest");
  EXPECT_EQ(cut["bone"], "B_ForeArm_Right");
  EXPECT_EQ(cut["kept_sections"].get<int>(), 1) << cut;
  EXPECT_GT(cut["sections"].get<int>(), 1) << cut;
  EXPECT_EQ(cut["loops"].get<int>(), 1) << cut;
  EXPECT_EQ(cut["capped_loops"].get<int>(), 1) << cut;
  EXPECT_EQ(cut["new_pieces"].get<int>(), 1) << cut;
  const Outcome plane = run(args + " --set cut.region=everywhere", "region_everywhere");
  ASSERT_EQ(plane.rc, 0) << plane.log;
  const Json& all = plane.summary["metrics"]["cut"];
  EXPECT_EQ(all["region"], "everywhere");
  EXPECT_GE(all["loops"].get<int>(), 3) << all;
  EXPECT_GE(all["new_pieces"].get<int>(), 3) << all;
  // Another name is refused, naming it.
  const Outcome bad = run("--steps 2" + kNoEdits + "--set cut.region=arm", "region_bad");
  EXPECT_NE(bad.rc, 0);
  EXPECT_NE(bad.log.find("cut.region"), std::string::npos) << bad.log;
}

}  // namespace
