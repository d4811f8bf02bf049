// The built-in scenes, run through the `conform` command, against physical expectations:
// tracking-error bounds of arm-track, gravity compensation holding an unpowered arm, a tear
// that opens by physics only under pretension, the cut/drill scenes following their skins,
// and a real model cut, torn and drilled while its animation plays, its seams kept closed. Each run
// is a few seconds of simulated time (well under a second of wall time in Release).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Runs `conform run SCENE ARGS` into a fresh folder; returns summary.json (null on failure).
Json run(const std::string& scene, const std::string& args, const std::string& tag) {
  const fs::path conform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
  if (!fs::exists(conform)) {
    ADD_FAILURE() << "build the conform command first: " << conform;
    return {};
  }
  const fs::path dir = fs::path(testing::TempDir()) / ("conform_scene_" + tag);
  fs::remove_all(dir);
  const std::string cmd = conform.string() + " run " + scene + " --out " + dir.string() +
                          " --set outputs.plots=false " + args + " > " + dir.string() + ".log 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream log(dir.string() + ".log");
  const std::string text((std::istreambuf_iterator<char>(log)), {});
  if (rc != 0) {
    ADD_FAILURE() << cmd << " failed:\n" << text;
    return {};
  }
  std::ifstream in(dir / "summary.json");
  Json summary = Json::parse(in, nullptr, false);
  EXPECT_TRUE(summary.is_object()) << "no summary.json in " << dir;
  return summary;
}

TEST(SceneArmTrack, FollowsTheIkTargetWithinBounds) {
  const Json s = run("arm-track", "", "arm_track");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  const Json& with = m["with_gravity_compensation"];
  const Json& without = m["without_gravity_compensation"];
  // Moving target (figure-eight 0.24 m/s, waypoints): a few millimetres of lag at most.
  EXPECT_LT(with["rms_error"].get<double>(), 0.004);
  EXPECT_LT(with["max_error"].get<double>(), 0.008);
  // Held waypoints: the servo settles onto the target.
  EXPECT_LT(with["steady_state_error"].get<double>(), 1e-4);
  EXPECT_LT(without["steady_state_error"].get<double>(), 1e-3);
  // The torque-limited servo saturates against gravity somewhere without compensation.
  EXPECT_GE(without["max_error"].get<double>(), with["max_error"].get<double>());
  EXPECT_EQ(m["rms_error"], with["rms_error"]);
  EXPECT_GT(m["ik_ns_per_solve"].get<double>(), 0);
  EXPECT_LT(m["ik_ns_per_solve"].get<double>(), 1e5);
  EXPECT_EQ(m["ik_targets_moved"].get<int>(), 0);
  // The CGA-skinned skin sits on Bullet's links (float Bullet: ~1e-7 m).
  EXPECT_LT(m["skin_max_offset_from_bones"].get<double>(), 1e-5);
  EXPECT_GT(s["timings"]["wall_per_simulated_second_s"].get<double>(), 0);
  EXPECT_GT(s["timings"]["wall_per_step_ms"].get<double>(), 0);
}

TEST(SceneArmTrack, GravityCompensationAloneHoldsAnUnpoweredArm) {
  // Motors without torque, a still target: only the feed-forward torques hold the arm up.
  const Json s = run("arm-track",
                     "--set arm.shoulder_max_torque=0 --set arm.elbow_max_torque=0 "
                     "--set targets.figure_eight.width=0 --set targets.figure_eight.height=0 "
                     "--set targets.figure_eight.duration=1 --set targets.waypoints.count=0",
                     "arm_hold");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_LT(m["with_gravity_compensation"]["max_error"].get<double>(), 2e-3);
  EXPECT_GT(m["without_gravity_compensation"]["max_error"].get<double>(), 0.05);  // it falls
}

TEST(SceneTearOpening, OpensByPhysicsUnderPrestressOnly) {
  const Json s = run("tear-opening", "--set duration=2 --set pose.flex_deg=90", "tear");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_GT(m["physics"]["tear_points"].get<int>(), 20);
  EXPECT_GT(m["physics"]["max_opening"].get<double>(), 0.003);
  EXPECT_GT(m["physics"]["profile_r2"].get<double>(), 0.5);
  EXPECT_GT(m["physics"]["opened_area"].get<double>(), 1e-4);
  // Step 6 moves the borders apart by the prescribed amount at the middle.
  EXPECT_NEAR(m["geometric"]["max_opening"].get<double>(), 0.01, 0.001);
  EXPECT_GT(m["geometric"]["tear_points"].get<int>(), 20);

  EXPECT_EQ(m["physics"]["material"], "membrane");
  EXPECT_EQ(m["physics"]["unconverged_substeps"].get<int>(), 0);
  EXPECT_LE(m["physics"]["residual"].get<double>(), 100.0);  // Pa, the default tolerance
  // After the stroke the elbow flexes 90 degrees (1.5-2 s): the skin over it stretches and the
  // physical wound gapes wider (+1.4 % at resolution 1 under the neo-Hookean law, +5 % under
  // StVK), converged in every substep (the skin wrinkles at the inner elbow); the geometric
  // opening stays as step 6 made it.
  EXPECT_GT(m["physics"]["max_opening"].get<double>(),
            1.007 * m["physics"]["max_opening_before_flex"].get<double>());
  EXPECT_LE(m["physics"]["residual_max"].get<double>(), 100.0);

  const Json slack =
      run("tear-opening", "--set duration=2 --set material.prestress=[0,0]", "slack");
  ASSERT_TRUE(slack.is_object());
  EXPECT_GT(slack["metrics"]["physics"]["tear_points"].get<int>(), 20);
  EXPECT_LT(slack["metrics"]["physics"]["max_opening"].get<double>(),
            0.2 * m["physics"]["max_opening"].get<double>());
}

// The tear runs along the forearm. With the pre-stress [2 sigma, sigma] around the limb its
// lips feel 2 sigma, along the limb sigma: on its foundation the long tear opens by
// 2 sigma_n l / E'' (l = sqrt(E'' t / k), E'' = 4 E / 3 for the incompressible neo-Hookean law),
// twice as wide around as along. sigma / E = 0.02 keeps it in the formula's small-strain range.
TEST(SceneTearOpening, ThePrestressAroundTheLimbOpensTheTearAlongIt) {
  const std::string common =
      "--set duration=1.5 --set outputs.frames_every=0 --set material.prestress=[16160,8080] ";
  const Json along =
      run("tear-opening", common + "--set material.prestress_field=along-bones", "field_along");
  const Json around =
      run("tear-opening", common + "--set material.prestress_field=around-bones", "field_around");
  ASSERT_TRUE(along.is_object() && around.is_object());
  const Json& mat = along["settings"]["material"];
  ASSERT_EQ(mat["law"], "neo-hookean");
  const double e2 = 4 * mat["youngs_modulus"].get<double>() / 3;
  const double l =
      std::sqrt(e2 * mat["thickness"].get<double>() / mat["attachment_stiffness"].get<double>());
  const auto w = [](const Json& s) { return s["metrics"]["physics"]["max_opening"].get<double>(); };
  EXPECT_NEAR(w(along) / (2 * 8080 * l / e2), 1.0, 0.03);    // measured 0.982
  EXPECT_NEAR(w(around) / (2 * 16160 * l / e2), 1.0, 0.03);  // measured 0.987
  EXPECT_NEAR(w(around) / w(along), 2.0, 0.04);              // measured 2.010
}

TEST(SceneCut, PiecesKeepSimulatingAndTheHandFollowsItsBones) {
  const Json s = run("cut", "--set duration=1.5", "cut");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_EQ(m["pieces"].get<int>(), 2);
  EXPECT_EQ(m["event"]["status"], "cut");
  EXPECT_GT(m["event"]["hand_piece_vertices"].get<int>(), 100);
  EXPECT_LT(m["hand_offset_max_over_time"].get<double>(), 0.01);
}

TEST(SceneDrill, TheRimStaysOnTheSkin) {
  const Json s = run("drill", "--set duration=1.5", "drill");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_EQ(m["event"]["holes"].get<int>(), 2);  // through both walls
  EXPECT_GT(m["event"]["rim_nodes"].get<int>(), 24);
  EXPECT_LT(m["rim_offset_max_over_time"].get<double>(), 0.01);
}

TEST(SceneCharacter, RealModelIsCutTornAndDrilledWhileItPlays) {
  if (!fs::exists("/usr/share/assimp/models/FBX/huesitos.fbx"))
    GTEST_SKIP() << "assimp-testmodels is not installed";
  // Bullet's links, and the edits placed in the bind pose's bounding box for huesitos (the
  // scene's placement before edits were aimed at limbs).
  const Json s = run("character",
                     "--set material.model=bullet_links "
                     "--set cut.point=[0.68,0.39,0.305] --set cut.normal=[1,0,-0.625] "
                     "--set tear.from=[0.1,0.75,1.0] --set tear.to=[0.3,0.75,1.0] "
                     "--set tear.blade_a=[0,0,0.3] --set tear.blade_b=[0,0,-0.45] "
                     "--set drill.tip=[0.6,0.2,0.68] --set drill.base=[-0.2,0.2,0.68] "
                     "--set drill.radius=0.03",
                     "character");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_EQ(m["vertices"].get<int>(), 62);  // 128 in the file, welded at its seams
  EXPECT_EQ(m["bones"].get<int>(), 9);
  EXPECT_GT(m["kinematic_nodes"].get<int>(), 0);
  EXPECT_GT(m["secondary_motion_mean_m"].get<double>(), 0);   // the soft nodes do lag
  EXPECT_LT(m["secondary_motion_max_m"].get<double>(), 1.0);  // the model spans ~8 m
  // No first-step spike: the body starts at the animation's first pose, so its fastest node
  // after one step moves no faster than the animation moves the skin, plus what gravity adds
  // in one step (g dt = 9.81 / 60 m/s).
  EXPECT_LE(m["first_step_max_node_speed_m_s"].get<double>(),
            m["first_step_max_target_speed_m_s"].get<double>() + 9.81 / 60);
  // The arm is cut off at 0.3 s by a capped cut that closes its loop: a new piece.
  const Json& cut = m["cut"];
  EXPECT_EQ(cut["status"], "cut");
  EXPECT_GE(cut["loops"].get<int>(), 1);
  EXPECT_EQ(cut["capped_loops"], cut["loops"]) << cut.dump();
  EXPECT_GE(cut["new_pieces"].get<int>(), 1);
  EXPECT_GE(m["pieces"].get<int>(), 2);
  // The flank torn from 0.5 s: the tear extends on at least 90 % of the samples after the
  // first, and its tip ends within 5 % of the diagonal of the last blade (the soft body lags).
  const Json& tear = m["tear"];
  EXPECT_GE(tear["extended_fraction"].get<double>(), 0.9) << tear.dump();
  EXPECT_GE(tear["tip_to_last_blade_rel"].get<double>(), 0);
  EXPECT_LT(tear["tip_to_last_blade_rel"].get<double>(), 0.05) << tear.dump();
  // The base drilled through at 1.1 s: both walls, joined by a tube. Each hole is at least
  // the disc πr² and at most 30 % more: the axis meets the octagonal tube at a ridge between
  // two faces, 1/cos 22.5° = 1.082 at rest, more where the pose tilts the wall.
  const Json& drill = m["drill"];
  EXPECT_EQ(drill["holes"].get<int>(), 2) << drill.dump();
  EXPECT_EQ(drill["tubes"].get<int>(), 1) << drill.dump();
  EXPECT_GE(drill["area_per_hole_vs_disc"].get<double>(), 1.0);
  EXPECT_LE(drill["area_per_hole_vs_disc"].get<double>(), 1.3);
  // The seams stay closed: the file's 114 vertices at 48 shared positions are welded into one
  // vertex each, so no gap opens across them (≤ 1e-6 of the diagonal).
  const Json& seams = m["seams"];
  EXPECT_EQ(seams["positions"].get<int>(), 48);
  EXPECT_EQ(seams["open_positions"].get<int>(), 0);
  EXPECT_LE(seams["max_gap_rel"].get<double>(), 1e-6);
}

TEST(SceneCharacter, WithoutTheWeldTheSeamsGapeAndTheEditsStopAtThem) {
  // The same run on the file's split vertices: the seam measure sees the pieces part (the
  // issue measured 1-4 % of the model's size), the cut meets the seams as open curves and is
  // not capped, and the tear stops early.
  if (!fs::exists("/usr/share/assimp/models/FBX/huesitos.fbx"))
    GTEST_SKIP() << "assimp-testmodels is not installed";
  const Json s = run("character", "--set model.weld=false", "character_split");
  ASSERT_TRUE(s.is_object());
  const Json& m = s["metrics"];
  EXPECT_EQ(m["seams"]["open_positions"].get<int>(), 48);
  EXPECT_GT(m["seams"]["max_gap_rel"].get<double>(), 0.01);
  EXPECT_EQ(m["cut"]["capped_loops"].get<int>(), 0);
  EXPECT_LT(m["tear"]["extended_fraction"].get<double>(), 0.5);
}

TEST(SceneCharacter, SeamCopiesWeightedApartWeldWithTheirMeanAndStayClosed) {
  // X/Testwuson.X weights 7 of its seam positions' copies differently. Welded with their mean
  // weights (the default) those seams stay closed as it plays; kept apart as the file has them
  // they open (0.42 % of the diagonal measured).
  const std::string file = "/usr/share/assimp/models/X/Testwuson.X";
  if (!fs::exists(file)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // Bullet's links: the seams are the weld's, whatever the skin. (At 100 units a metre, a 3 cm
  // animal, the links' step went non-finite after the drill; in metres it does not.)
  const std::string links = " --set material.model=bullet_links";
  const Json mean = run("character", "--set model.file=" + file + links, "character_wuson");
  ASSERT_TRUE(mean.is_object());
  const Json& closed = mean["metrics"]["seams"];
  EXPECT_EQ(closed["mean_weight_positions"].get<int>(), 7);
  EXPECT_EQ(closed["open_positions"].get<int>(), 0);
  EXPECT_LE(closed["max_gap_rel"].get<double>(), 1e-6);
  const Json apart =
      run("character", "--set model.file=" + file + links + " --set model.seam_weights=keep_apart",
          "character_wuson_apart");
  ASSERT_TRUE(apart.is_object());
  const Json& open = apart["metrics"]["seams"];
  EXPECT_EQ(open["kept_apart_vertices"].get<int>(), 7);
  EXPECT_EQ(open["open_positions"].get<int>(), 7);
  EXPECT_GT(open["max_gap_rel"].get<double>(), 1e-3);
}

TEST(SceneCharacter, SeparateObjectsThatTouchAreNotSeams) {
  // Collada/anims_with_full_rotations_between_keys.DAE: boxes, each its own mesh on its own
  // bone, share 8 corner positions. They part as they turn (the seam measure read 1.93 of the
  // diagonal when it counted them), but they are separate objects, not an open seam.
  const std::string file =
      "/usr/share/assimp/models/Collada/anims_with_full_rotations_between_keys.DAE";
  if (!fs::exists(file)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // At 100 units a metre (its <unit> says metres but is named centimetre): in metres it is a
  // 120 m chain whose boxes turn full circles between keys, and its skin lags them by over
  // 100 m/s within 0.05 s, which the run stops as a runaway (docs/scenes.md).
  const Json s = run("character", "--set model.units_per_metre=100 --set model.file=" + file,
                     "character_boxes");
  ASSERT_TRUE(s.is_object());
  const Json& seams = s["metrics"]["seams"];
  EXPECT_EQ(seams["touching_positions"].get<int>(), 8);
  EXPECT_EQ(seams["open_positions"].get<int>(), 0);
  EXPECT_LE(seams["max_gap_rel"].get<double>(), 1e-6);
  // Each box is a limb whose section's rings are its ends, so the cut (before the drill)
  // releases one end, and the ring on it falls away: the drill is carried by the box's bone
  // instead of the skin (it missed, aimed by the fallen ring, before).
  const Json& drill = s["metrics"]["drill"];
  EXPECT_EQ(drill["status"].get<std::string>(), "drilled");
  EXPECT_EQ(drill["held_by"].get<std::string>(), "bone");
}

}  // namespace
