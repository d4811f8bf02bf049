// The skin membrane on a user's own character (huesitos.fbx as imported: its mesh space is 100
// times smaller than its bind pose): the skin's rest state is the bind pose, so the membrane
// follows the animation at least as closely as Bullet's links, with no seam opening.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "conform_run.hpp"

namespace {

using Json = nlohmann::json;

Json metrics(const std::string& model, const std::string& tag) {
  const conform::test::CommandRun r = conform::test::run_conform_scene(
      "character", "--set outputs.plots=false --set material.model=" + model, tag);
  EXPECT_EQ(r.rc, 0) << r.log;
  EXPECT_TRUE(r.summary.is_object()) << r.log;
  return r.summary.is_object() ? r.summary["metrics"] : Json();
}

TEST(SceneCharacterMembrane, FollowsTheAnimationAtLeastAsCloselyAsTheLinks) {
  const Json membrane = metrics("membrane", "character_membrane");
  const Json links = metrics("bullet_links", "character_links");
  ASSERT_TRUE(membrane.is_object() && links.is_object());
  const double mean = membrane["secondary_motion_mean_m"],
               links_mean = links["secondary_motion_mean_m"];
  std::printf("secondary motion, mean: membrane %.4g m, links %.4g m; max %.4g / %.4g m\n", mean,
              links_mean, membrane["secondary_motion_max_m"].get<double>(),
              links["secondary_motion_max_m"].get<double>());
  EXPECT_LE(mean, links_mean);
  EXPECT_LT(mean, 0.01);  // on an 8 m figure
  EXPECT_EQ(membrane["seams"]["max_gap_rel"].get<double>(), 0);
  // The wound opens like the geometric one, not by metres.
  EXPECT_LT(membrane["physics"]["max_opening"].get<double>(),
            3 * membrane["geometric"]["max_opening"].get<double>());
  // Every step's solve converged to the material's relative tolerance; the links have none.
  const Json& solve = membrane["solver"];
  EXPECT_EQ(solve["unconverged_steps"].get<int>(), 0) << solve;
  EXPECT_LE(solve["worst_relative_residual"].get<double>(), 1.2e-3) << solve;
  EXPECT_GE(solve["newton_mean"].get<double>(), 1) << solve;  // the animation moves it
  EXPECT_FALSE(links.contains("solver"));
}

}  // namespace
