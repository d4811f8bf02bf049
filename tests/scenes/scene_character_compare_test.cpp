// The character scene's tear, physical against geometric (as tear-opening on the arm): both
// openings reported in metres with their profiles, plots' data and pictures, and the geometric
// copy (the same stroke on the animated mesh alone, opened by Algorithm 2 step 6) owing nothing
// to the physics. Each run is the `conform` command on huesitos.fbx, cut to the stroke and a
// few steps of opening (60 steps of 1/60 s; the drill, at 1.1 s, is off).
#include <gtest/gtest.h>

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

const std::string kHuesitos = "/usr/share/assimp/models/FBX/huesitos.fbx";
const std::string kShort = " --steps 60 --set drill.enabled=false --set outputs.plots=false ";

using Outcome = conform::test::CommandRun;

// `conform run character ARGS` into a fresh folder.
Outcome run(const std::string& args, const std::string& tag) {
  return conform::test::run_conform_scene("character", kShort + args, "character_compare_" + tag);
}

// The first line of a CSV file (its columns), "" when it cannot be read.
std::string header(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  return line;
}

TEST(SceneCharacterCompare, BothOpeningsInMetresWithProfilesAndPictures) {
  if (!fs::exists(kHuesitos)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // One picture, of the last step (frames_every 0), rendered by f3d when it is installed.
  const Outcome r = run("--set outputs.frames_every=0", "pictures");
  ASSERT_EQ(r.rc, 0) << r.log;
  ASSERT_TRUE(r.summary.is_object()) << r.log;
  const Json& m = r.summary["metrics"];
  const double diagonal = m["seams"]["diagonal_m"].get<double>();
  ASSERT_GT(diagonal, 1.0);  // huesitos is ~8 m tall in metres
  const double phys = m["physics"]["max_opening"].get<double>();
  const double geom = m["geometric"]["max_opening"].get<double>();
  EXPECT_GT(phys, 0) << m.dump(1);
  EXPECT_GT(geom, 0) << m.dump(1);
  // The geometric opening is geometric.amount of the diagonal at the middle of the tear,
  // tapered by a sine: at most that, and most of it at the path point nearest the middle.
  EXPECT_DOUBLE_EQ(m["geometric"]["amount"].get<double>(), 0.01);
  EXPECT_NEAR(m["geometric"]["amount_m"].get<double>(), 0.01 * diagonal, 1e-12);
  EXPECT_LE(geom, 0.01 * diagonal * (1 + 1e-9));
  EXPECT_GT(geom, 0.5 * 0.01 * diagonal);
  // In metres: both openings are a small part of the ~8 m model, not file units (cm).
  EXPECT_LT(phys, 0.1 * diagonal);
  EXPECT_GE(m["physics"]["tear_points"].get<int>(), 2);
  EXPECT_GE(m["geometric"]["tear_points"].get<int>(), 2);
  EXPECT_NEAR(m["physics_over_geometric_max_opening"].get<double>(), phys / geom, 1e-9);
  // The new keys are echoed in the settings.
  const Json& settings = r.summary["settings"];
  EXPECT_DOUBLE_EQ(settings["geometric"]["amount"].get<double>(), 0.01);
  EXPECT_EQ(settings["profiles"]["snapshots"].get<int>(), 6);
  EXPECT_EQ(settings["profiles"]["points"].get<int>(), 41);
  // The profiles, the metrics' opening columns, the geometric frames.
  EXPECT_EQ(header(r.dir / "profile_history.csv"), "t,s,physics_width,geometric_width");
  EXPECT_EQ(header(r.dir / "profiles.csv").rfind("s,physics_", 0), 0u)
      << header(r.dir / "profiles.csv");
  EXPECT_NE(header(r.dir / "metrics.csv").find("physics_max_opening,geometric_max_opening"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(r.dir / "frames" / "geometric_000060.ply"));
  EXPECT_TRUE(fs::exists(r.dir / "frames" / "character_000060.ply"));
  if (std::system("command -v f3d > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(fs::exists(r.dir / "pictures" / "step_000060.png")) << r.summary["render"].dump();
    EXPECT_TRUE(fs::exists(r.dir / "pictures" / "panels" / "strip_000060.png"));
    // Coloured by the gap across the lips, in metres: at most the model's size (an edge strain
    // against the mesh-space rest positions read +-119 on this model).
    const Json& scale = r.summary["render"]["scale"];
    EXPECT_EQ(scale["scalar"], "gap");
    EXPECT_GT(scale["max"].get<double>(), 0.0);
    EXPECT_LT(scale["max"].get<double>(), diagonal);
  }
}

TEST(SceneCharacterCompare, TheGeometricOpeningOwesNothingToThePhysics) {
  if (!fs::exists(kHuesitos)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // The same run with gravity 4 times stronger: the body moves otherwise, its wound opens
  // otherwise; the geometric copy, posed by the animation and torn on its own skin, does not
  // change at all.
  const Outcome a = run("--no-render", "base");
  const Outcome b = run("--no-render --set physics.gravity=[0,-39.24,0]", "heavier");
  ASSERT_EQ(a.rc, 0) << a.log;
  ASSERT_EQ(b.rc, 0) << b.log;
  const Json &ma = a.summary["metrics"], &mb = b.summary["metrics"];
  EXPECT_EQ(ma["geometric"], mb["geometric"]) << ma["geometric"].dump() << "\n"
                                              << mb["geometric"].dump();
  const double pa = ma["physics"]["max_opening"].get<double>();
  const double pb = mb["physics"]["max_opening"].get<double>();
  EXPECT_GT(std::abs(pa - pb), 1e-3 * std::max(pa, pb)) << pa << " against " << pb;
}

}  // namespace
