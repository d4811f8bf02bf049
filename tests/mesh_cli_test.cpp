// The `conform cut|tear|drill` subcommands, run as a process (skipped when the command has
// not been built in this build tree).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

const fs::path kConform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";

fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("conform_mesh_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

int run(const std::string& args) {
  const std::string cmd = kConform.string() + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json summary(const fs::path& dir) {
  std::ifstream is(dir / "summary.json");
  return nlohmann::json::parse(is);
}

// Only the pieces and summary.json are written.
void expect_only_outputs(const fs::path& dir, int pieces, const std::string& ext) {
  int meshes = 0, others = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name == "summary.json") continue;
    (e.path().extension() == ext && name.rfind("piece_", 0) == 0 ? meshes : others)++;
  }
  EXPECT_EQ(meshes, pieces);
  EXPECT_EQ(others, 0);
}

}  // namespace

class MeshCli : public testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kConform)) GTEST_SKIP() << "conform not built at " << kConform;
  }
};

TEST_F(MeshCli, CutWithCapWritesClosedPieces) {
  const fs::path d = fresh_dir("cut");
  ASSERT_EQ(run("cut arm --plane 0 0.2 1 0.3 --cap --out " + d.string()), 0);
  const auto s = summary(d);
  EXPECT_EQ(s["output"]["pieces"], 2);
  EXPECT_EQ(s["output"]["closed"], true);
  EXPECT_EQ(s["output"]["manifold"], true);
  EXPECT_EQ(s["input"]["faces"], 5120);
  EXPECT_TRUE(s["timing_ms"].contains("operation"));
  expect_only_outputs(d, 2, ".ply");
  fs::remove_all(d);
}

TEST_F(MeshCli, DrillAndTear) {
  const fs::path d = fresh_dir("drill");
  ASSERT_EQ(run("drill arm --tip 0 -0.2 0.4 --base 0 0.2 0.4 --radius 0.01 --format obj --out " +
                d.string()),
            0);
  EXPECT_EQ(summary(d)["holes"], 2);
  EXPECT_EQ(summary(d)["output"]["closed"], false);
  expect_only_outputs(d, 1, ".obj");
  fs::remove_all(d);
  // With the tube wall (and rings) the drilled arm stays closed.
  ASSERT_EQ(run("drill arm --tip 0 -0.2 0.4 --base 0 0.2 0.4 --radius 0.01 --tube --tube-rings 2 "
                "--out " +
                d.string()),
            0);
  EXPECT_EQ(summary(d)["tube"]["tubes"], 1);
  EXPECT_GT(summary(d)["tube"]["faces"], 66);
  EXPECT_EQ(summary(d)["output"]["closed"], true);
  EXPECT_EQ(summary(d)["output"]["manifold"], true);
  fs::remove_all(d);

  const fs::path t = fresh_dir("tear");
  fs::create_directories(t);
  {
    std::ofstream csv(t / "scalpel.csv");
    csv << "t,ax,ay,az,bx,by,bz\n";
    for (int i = 0; i < 50; ++i) {
      const double z = 0.1 + 0.1 * i / 49.0;
      csv << i << ",0,0," << z << ",0.2,0.03," << z << "\n";
    }
  }
  const fs::path out = t / "out";
  ASSERT_EQ(run("tear arm --scalpel " + (t / "scalpel.csv").string() + " --open 0.004 --out " +
                out.string()),
            0);
  const auto s = summary(out);
  EXPECT_EQ(s["tear"]["steps"], 49);
  EXPECT_EQ(s["output"]["pieces"], 1);
  expect_only_outputs(out, 1, ".ply");
  fs::remove_all(t);
}

TEST_F(MeshCli, ErrorsExitNonZero) {
  const fs::path d = fresh_dir("errors");
  EXPECT_NE(run("drill arm --tip 0 0 0 --base 0 0 1 --radius 0 --out " + d.string()), 0);
  EXPECT_NE(run("drill arm --tip 5 5 0 --base 5 5 1 --radius 0.01 --out " + d.string()),
            0);  // misses
  EXPECT_NE(run("drill arm --tip 0 -0.2 0.4 --base 0 0.2 0.4 --radius 0.01 --tube-rings 2 --out " +
                d.string()),
            0);  // rings without a tube
  EXPECT_NE(run("tear missing_model.fbx --scalpel x.csv --out " + d.string()), 0);
  EXPECT_NE(run("cut arm --plane 0 0 nan 0 --out " + d.string()), 0);
  EXPECT_NE(run("cut arm --plane 0 0 1 --out " + d.string()), 0);  // three numbers
  // A plane that misses is a documented no-op: the whole model is written as one piece.
  EXPECT_EQ(run("cut arm --plane 0 0 1 5 --out " + d.string()), 0);
  EXPECT_EQ(summary(d)["status"], "missed");
  fs::remove_all(d);
}
