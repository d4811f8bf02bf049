// The pieces a cut severs fall: in `character` (by default) and in `cut` (cut.release), the
// severed piece is released from skinning, keeps its volume when capped, falls onto the ground
// and rests on it, at its collision margin above the ground's top. Every reference is taken
// from the run's own settings (the margin, the ground's height) or from Bullet's free fall.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "conform_run.hpp"

using conform::test::run_conform_scene;

namespace {

// The runs' collision margin, m: a resting piece stands on it (Bullet's soft contacts hold a
// node at the margin from a rigid surface).
const std::string kMargin = "--set material.margin=0.001 ";

// The released piece of a run: landed on the ground (its lowest node within 1 mm of the
// ground's top, and not below it), at rest, its volume kept within 10 %.
void expect_landed(const nlohmann::json& summary, double fallen_at_least) {
  const auto& m = summary["metrics"];
  ASSERT_TRUE(m.contains("released_pieces")) << m.dump();
  ASSERT_EQ(m["released_pieces"].size(), 1u) << m["released_pieces"].dump();
  const auto& piece = m["released_pieces"][0];
  EXPECT_GE(piece["lowest_above_ground_end_m"].get<double>(), 0.0) << piece.dump();
  EXPECT_LE(piece["lowest_above_ground_end_m"].get<double>(), 1e-3) << piece.dump();
  EXPECT_LT(piece["speed_end_m_per_s"].get<double>(), 0.05) << piece.dump();
  EXPECT_NEAR(piece["volume_kept_end"].get<double>(), 1.0, 0.1) << piece.dump();
  EXPECT_GT(piece["fall_m"].get<double>(), fallen_at_least) << piece.dump();
}

}  // namespace

TEST(SceneFallingPieces, TheCharactersSeveredArmFallsOntoTheGroundAndRests) {
  // With the membrane skin (the scene's default) and with Bullet's links: over the ground the
  // released piece is damped at least as the links are (kDP 0.01), also from a membrane body.
  for (const std::string model : {"membrane", "bullet_links"}) {
    SCOPED_TRACE(model);
    const auto r = run_conform_scene(
        "character",
        kMargin + "--set duration=2.5 --set render=false --set material.model=" + model,
        "fall_c_" + model);
    ASSERT_EQ(r.rc, 0) << r.log;
    const auto& m = r.summary["metrics"];
    EXPECT_EQ(m["cut"]["status"], "cut");
    ASSERT_EQ(m["cut"]["released"].size(), 1u);
    EXPECT_TRUE(m["cut"]["released"][0]["closed"].get<bool>());  // capped: it keeps a volume
    // The ground is under the bind pose's lowest point by default.
    EXPECT_DOUBLE_EQ(m["ground"]["height_m"].get<double>(), m["bind_pose_lo_m"][1].get<double>());
    // huesitos' arm is about 1.8 m above its feet when it is cut off.
    expect_landed(r.summary, 1.0);
  }
}

TEST(SceneFallingPieces, TheArmsReleasedHandLandsWhereTheGroundIsAndFallsOnWithoutIt) {
  // 4 substeps: at the scene's 2 a dropped hand keeps 87-91 % of its volume
  // (tests/plugin/plugin_release_test.cpp measures the step's part).
  const std::string release = kMargin +
                              "--set render=false --set cut.release=true --set cut.cap=true "
                              "--set physics.substeps=4 ";
  const auto on = run_conform_scene("cut", release + "--set ground.enabled=true", "fall_on");
  ASSERT_EQ(on.rc, 0) << on.log;
  expect_landed(on.summary, 0.1);
  // The skinned rest of the arm does not meet the ground: its offsets are those of a run
  // without ground.
  const auto off = run_conform_scene("cut", release + "--set ground.enabled=false", "fall_off");
  ASSERT_EQ(off.rc, 0) << off.log;
  const auto& piece = off.summary["metrics"]["released_pieces"][0];
  ASSERT_TRUE(piece.contains("lowest_y_end_m")) << piece.dump();
  // Without it the hand falls freely for 2.5 s: far below where the ground would have been.
  EXPECT_LT(piece["lowest_y_end_m"].get<double>(), -0.5 - 10.0) << piece.dump();
  EXPECT_DOUBLE_EQ(on.summary["metrics"]["offset_max"].get<double>(),
                   off.summary["metrics"]["offset_max"].get<double>());
}

TEST(SceneFallingPieces, ABadGroundOrModulusIsRefusedByName) {
  const auto height = run_conform_scene("cut", "--set ground.height=[1,2]", "fall_bad_h");
  EXPECT_NE(height.rc, 0);
  EXPECT_NE(height.log.find("ground.height"), std::string::npos) << height.log;
  const auto modulus = run_conform_scene("character", "--set cut.volume_modulus=-3", "fall_bad_k");
  EXPECT_NE(modulus.rc, 0);
  EXPECT_NE(modulus.log.find("cut.volume_modulus"), std::string::npos) << modulus.log;
}
