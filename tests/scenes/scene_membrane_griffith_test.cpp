// membrane-griffith through the `conform` command: a slit in a sheet stretched at its border
// starts to grow at Griffith's stress sqrt(E G_c / (pi a)) (plane stress) whatever its length,
// the toughness or the elements at its tips, and an inclined slit under a uniaxial load first
// grows in the direction of the maximum tangential stress. Every reference is computed here from
// the settings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "conform_run.hpp"

namespace {

using Json = nlohmann::json;
constexpr double kE = 420000;  // the scene's Young's modulus, Pa

double griffith(double a, double toughness) {
  return std::sqrt(kE * toughness / (std::numbers::pi * a));
}

// The load, in units of Griffith's stress s_g: preloaded to 0.8 s_g and ramped to reach s_g at
// t = 0.25 s (25 steps of 0.01 s: the onset is resolved to 0.8 % of it at every size), a short
// run past it.
std::string ramp(double s_g) {
  return "--set outputs.plots=false --set duration=0.28 --set growth.step_length=0.0005 "
         "--set load.preload=" +
         std::to_string(0.8 * s_g) + " --set load.rate=" + std::to_string(0.2 * s_g / 0.25) + " ";
}

Json run(double a, double toughness, const std::string& extra, const std::string& tag) {
  const std::string args = ramp(griffith(a, toughness)) +
                           "--set slit.half_length=" + std::to_string(a) +
                           " --set material.toughness=" + std::to_string(toughness) + " " + extra;
  const conform::test::CommandRun r =
      conform::test::run_conform_scene("membrane-griffith", args, "griffith_" + tag);
  EXPECT_EQ(r.rc, 0) << r.log;
  EXPECT_TRUE(r.summary.is_object()) << r.log;
  return r.summary.is_object() ? r.summary["metrics"] : Json();
}

double onset_over_griffith(const Json& m, double a, double toughness) {
  if (!m.contains("onset_stress")) {
    ADD_FAILURE() << "no growth: " << m.dump();
    return 0;
  }
  EXPECT_NEAR(m["griffith_stress"].get<double>(), griffith(a, toughness),
              1e-9 * griffith(a, toughness));
  const double ratio = m["onset_stress"].get<double>() / griffith(a, toughness);
  std::printf("a %.4g G_c %.3g: onset %.6g Pa, Griffith %.6g Pa, ratio %.4f\n", a, toughness,
              m["onset_stress"].get<double>(), griffith(a, toughness), ratio);
  return ratio;
}

TEST(SceneMembraneGriffith, OnsetAtGriffithsStressForThreeSlitLengths) {
  for (const double a : {0.0125, 0.025, 0.05}) {
    const Json m = run(a, 0.1, "", "a" + std::to_string(int(a * 1e4)));
    EXPECT_NEAR(onset_over_griffith(m, a, 0.1), 1.0, 0.05) << a;
  }
}

TEST(SceneMembraneGriffith, OnsetAtGriffithsStressForTwoToughnesses) {
  for (const double toughness : {0.05, 0.4}) {
    const Json m = run(0.025, toughness, "", "gc" + std::to_string(int(toughness * 100)));
    EXPECT_NEAR(onset_over_griffith(m, 0.025, toughness), 1.0, 0.05) << toughness;
  }
}

TEST(SceneMembraneGriffith, HalvingTheTipElementsChangesTheOnsetLittle) {
  const Json coarse = run(0.025, 0.1, "--set sheet.tip_refinement=16", "tips16");
  const Json fine = run(0.025, 0.1, "--set sheet.tip_refinement=32", "tips32");
  ASSERT_TRUE(coarse.contains("onset_stress") && fine.contains("onset_stress"));
  const double change =
      fine["onset_stress"].get<double>() / coarse["onset_stress"].get<double>() - 1;
  // At the same load step the energy release rates compare directly.
  const double g_change = fine["onset_g"].get<double>() / coarse["onset_g"].get<double>() - 1;
  std::printf("tip elements halved: onset change %.4f, G at onset %.4f\n", change, g_change);
  EXPECT_LT(std::abs(change), 0.03);
  if (fine["onset_time"] == coarse["onset_time"]) {
    EXPECT_LT(std::abs(g_change), 0.03);
  }
}

TEST(SceneMembraneGriffith, InclinedSlitsKinkAtTheMtsAngle) {
  for (const int beta : {30, 45, 60}) {
    // Uniaxial load: K_I = sigma cos^2 b sqrt(pi a), K_II = sigma sin b cos b sqrt(pi a).
    const double b = beta * std::numbers::pi / 180, k1 = std::cos(b) * std::cos(b),
                 k2 = std::sin(b) * std::cos(b);
    const double mts =
        2 * std::atan((k1 - std::sqrt(k1 * k1 + 8 * k2 * k2)) / (4 * k2)) * 180 / std::numbers::pi;
    // G = pi a sigma^2 cos^2 b / E at onset (sigma = sigma_yy): the ramp reaches it at 0.25 s.
    const double a = 0.025, toughness = 0.1;
    const conform::test::CommandRun r = conform::test::run_conform_scene(
        "membrane-griffith",
        ramp(griffith(a, toughness) / std::cos(b)) +
            "--set load.ratio=0 --set slit.angle_deg=" + std::to_string(beta),
        "griffith_kink" + std::to_string(beta));
    ASSERT_EQ(r.rc, 0) << r.log;
    const Json& m = r.summary["metrics"];
    ASSERT_TRUE(m.contains("kink_deg")) << m.dump();
    std::printf("slit at %d deg: kink %.3f deg (path %.3f), MTS %.3f deg\n", beta,
                m["kink_deg"].get<double>(), m["path_kink_deg"].get<double>(), mts);
    EXPECT_NEAR(m["mts_kink_deg"].get<double>(), mts, 1e-9);
    EXPECT_NEAR(m["kink_deg"].get<double>(), mts, 5.0) << beta;
    // Every setting is echoed.
    EXPECT_EQ(r.summary["settings"]["slit"]["angle_deg"].get<double>(), beta);
    EXPECT_EQ(r.summary["settings"]["load"]["ratio"].get<double>(), 0);
  }
}

TEST(SceneMembraneGriffith, RefusesAPrestress) {
  const conform::test::CommandRun r = conform::test::run_conform_scene(
      "membrane-griffith", "--steps 1 --set material.prestress=[100,100]", "griffith_prestress");
  EXPECT_NE(r.rc, 0);
  EXPECT_NE(r.log.find("material.prestress"), std::string::npos) << r.log;
}

}  // namespace
