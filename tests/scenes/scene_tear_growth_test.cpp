// tear-opening with tear.growth through the `conform` command: the arm's energy release rate at
// its incision's tips is the membrane-on-foundation's sigma^2 l / E'' (l = sqrt(E'' t / k), the
// attachment's decay length: the foundation caps G whatever the incision's length), converged
// in the mesh; the incision grows by itself during an elbow flex at a toughness just above the
// unflexed G, and not at ten times it. Every reference is computed from the echoed settings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "conform_run.hpp"

namespace {

using Json = nlohmann::json;

Json run(const std::string& args, const std::string& tag) {
  const conform::test::CommandRun r = conform::test::run_conform_scene(
      "tear-opening", "--set tear.growth=true --set outputs.plots=false " + args, tag);
  EXPECT_EQ(r.rc, 0) << r.log;
  EXPECT_TRUE(r.summary.is_object()) << r.log;
  return r.summary.is_object() ? r.summary : Json();
}

// sigma^2 l / E'': each lip of a long cut in a pre-stressed membrane on a foundation retracts
// by sigma l / E'' (membrane-edge), releasing sigma u / 2 per unit length and thickness.
double foundation_g(const Json& settings) {
  const Json& m = settings["material"];
  const double E = m["youngs_modulus"], t = m["thickness"], k = m["attachment_stiffness"];
  // The neo-Hookean membrane is incompressible: nu = 0.5 at small strain.
  const double nu = m["law"] == "neo-hookean" ? 0.5 : m["poisson_ratio"].get<double>();
  const double sigma = m["prestress"][0], e2 = E / (1 - nu * nu);
  const double decay = std::sqrt(e2 * t / k);
  return sigma * sigma * decay / e2;
}

TEST(SceneTearGrowth, ArmsEnergyReleaseRateIsTheFoundationsAndConverged) {
  // The stroke ends at 1 s; G is judged from then on, still (no flex).
  const Json coarse = run("--set duration=1.2 --set material.toughness=1e6", "growth_res1");
  const Json fine = run("--set duration=1.2 --set material.toughness=1e6 --set model.resolution=2",
                        "growth_res2");
  ASSERT_TRUE(coarse.is_object() && fine.is_object());
  const double reference = foundation_g(coarse["settings"]);
  const double g1 = coarse["metrics"]["physics"]["max_energy_release_rate"];
  const double g2 = fine["metrics"]["physics"]["max_energy_release_rate"];
  std::printf("arm G: resolution 1 %.6g, resolution 2 %.6g J/m^2; sigma^2 l / E'' %.6g\n", g1, g2,
              reference);
  EXPECT_NEAR(g1 / reference, 1.0, 0.10);
  EXPECT_NEAR(g2 / g1, 1.0, 0.03);
  EXPECT_EQ(coarse["metrics"]["physics"]["grown_length"].get<double>(), 0);
  // Both tips are reported, each with its mode mix (G = (K_I^2 + K_II^2) / E' by construction).
  ASSERT_EQ(coarse["metrics"]["physics"]["tips"].size(), 2u);
  for (const Json& tip : coarse["metrics"]["physics"]["tips"]) {
    EXPECT_GT(tip["energy_release_rate"].get<double>(), 0);
    EXPECT_GT(tip["k1"].get<double>(), 0);
  }
}

TEST(SceneTearGrowth, IncisionGrowsDuringTheFlexAboveItsStillGAndNotAtTenTimesIt) {
  const std::string flex = "--set duration=2.2 --set pose.flex_deg=110 ";
  const Json grows = run(flex + "--set material.toughness=600", "growth_600");
  const Json holds = run(flex + "--set material.toughness=6000", "growth_6000");
  ASSERT_TRUE(grows.is_object() && holds.is_object());
  const Json& g = grows["metrics"]["physics"];
  std::printf("toughness 600: grown %.4g m from t = %.4g s (flex from %.4g s), G max %.5g\n",
              g["grown_length"].get<double>(), g["growth_onset_time"].get<double>(),
              grows["settings"]["pose"]["flex_at"].get<double>(),
              g["max_energy_release_rate"].get<double>());
  EXPECT_GT(g["grown_length"].get<double>(), 0.005);
  EXPECT_GT(g["growth_onset_time"].get<double>(),
            grows["settings"]["pose"]["flex_at"].get<double>());
  EXPECT_GT(g["max_energy_release_rate"].get<double>(), 600);
  EXPECT_EQ(g["toughness"].get<double>(), 600);
  EXPECT_LT(g["growth_mass_error"].get<double>(), 1e-9);
  EXPECT_LT(g["growth_momentum_error"].get<double>(), 1e-9);
  const Json& h = holds["metrics"]["physics"];
  EXPECT_EQ(h["grown_length"].get<double>(), 0);
  EXPECT_LT(h["max_energy_release_rate"].get<double>(), 6000);
  EXPECT_EQ(h["growth_onset_time"].get<double>(), -1);
}

TEST(SceneTearGrowth, GrowthNeedsTheMembrane) {
  const conform::test::CommandRun r = conform::test::run_conform_scene(
      "tear-opening", "--set tear.growth=true --set material.model=bullet_links", "growth_links");
  EXPECT_NE(r.rc, 0);
  EXPECT_NE(r.log.find("tear.growth"), std::string::npos) << r.log;
}

}  // namespace
