// The `conform skin` command writes what the library computes (world space, one file per
// frame) and fails cleanly on bad arguments. Needs the `conform` binary of this build tree.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "conform/io/import.hpp"
#include "conform/skin/skinner.hpp"

namespace {

namespace fs = std::filesystem;
using namespace conform;

const std::string kConform = std::string(CONFORM_BINARY_DIR) + "/scenes/conform";
const std::string kSimple =
    std::string(CONFORM_ASSIMP_MODELS) + "/glTF2/simple_skin/simple_skin.gltf";

Eigen::Matrix3Xd read_obj(const fs::path& p) {
  std::ifstream in(p);
  std::vector<Eigen::Vector3d> v;
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("v ", 0) == 0) {
      std::istringstream s(line.substr(2));
      Eigen::Vector3d x;
      s >> x.x() >> x.y() >> x.z();
      v.push_back(x);
    }
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = v[i];
  return m;
}

// The OBJ's positions per vertex of `mesh`, through the faces' corners: the file has one vertex
// per seam corner (a welded model is written with its seams), in the mesh's face order.
Eigen::Matrix3Xd read_obj_by_vertex(const fs::path& p, const mesh::SkinnedMesh& mesh) {
  const Eigen::Matrix3Xd v = read_obj(p);
  std::ifstream in(p);
  std::string line;
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Constant(3, mesh.vertex_count(), NAN);
  std::size_t f = 0;
  while (std::getline(in, line) && f < mesh.faces.size())
    if (line.rfind("f ", 0) == 0) {
      std::istringstream s(line.substr(2));
      for (int k = 0; k < 3; ++k) {
        std::string corner;
        s >> corner;
        out.col(mesh.faces[f][static_cast<std::size_t>(k)]) = v.col(std::stoi(corner) - 1);
      }
      ++f;
    }
  return out;
}

int run(const std::string& args) {
  return std::system((kConform + " skin " + args + " > /dev/null 2>&1").c_str());
}

class SkinCli : public testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kConform)) GTEST_SKIP() << "conform not built";
    // One folder per test process: ctest runs this file's tests in parallel processes, and a
    // shared folder let one test's SetUp delete another's outputs while it read them.
    dir = fs::path(testing::TempDir()) / ("conform_skin_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  fs::path dir;
};

TEST_F(SkinCli, WritesThePosedMeshInWorldSpace) {
  for (const char* mode : {"lbs", "versor"}) {
    const fs::path out = dir / (std::string(mode) + ".obj");
    ASSERT_EQ(run(kSimple + " --time 2.25 --blend log --mode " + mode + " --out " + out.string()),
              0);
    const auto model = io::import_model(kSimple);
    skin::Skinner<double> s(model.skeleton, model.mesh.rest, model.influences);
    skin::Pose pose;
    model.animations[0].sample(model.skeleton, 2.25, skin::Blend::log, pose);
    s.skin(pose, *skin::parse_skin_mode(mode));
    Eigen::Matrix3Xd expected;
    s.write(expected);
    const Eigen::Matrix3Xd got = read_obj(out);
    ASSERT_EQ(got.cols(), expected.cols());
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT((expected - model.mesh.current).cwiseAbs().maxCoeff(), 0.1);  // really posed
  }
}

TEST_F(SkinCli, FramesWriteOneFilePerFrame) {
  ASSERT_EQ(run(kSimple + " --frames 3 --out " + (dir / "f.ply").string()), 0);
  EXPECT_TRUE(fs::exists(dir / "f_0000.ply"));
  EXPECT_TRUE(fs::exists(dir / "f_0002.ply"));
  EXPECT_FALSE(fs::exists(dir / "f_0003.ply"));
  // A model without animations gives its bind pose.
  ASSERT_EQ(run("arm --time 3 --out " + (dir / "arm.obj").string()), 0);
  const auto arm = io::load_model("arm");
  EXPECT_LT((read_obj(dir / "arm.obj") - arm.mesh.rest).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(SkinCli, BadArgumentsFail) {
  const std::string out = " --out " + (dir / "x.obj").string();
  EXPECT_NE(run(kSimple + out), 0);                              // neither --time nor --frames
  EXPECT_NE(run(kSimple + " --time 1 --frames 2" + out), 0);     // both
  EXPECT_NE(run(kSimple + " --time 1 --animation 7" + out), 0);  // no such animation
  EXPECT_NE(run(kSimple + " --time 1 --blend cubic" + out), 0);
  EXPECT_NE(run(kSimple + " --time 1 --mode matrix" + out), 0);
  EXPECT_NE(run(kSimple + " --time 1 --out " + (dir / "x.stl").string()), 0);
  EXPECT_NE(run(std::string(CONFORM_TEST_DATA) + "/broken/notes_renamed.fbx --time 0" + out), 0);
  EXPECT_NE(run("arm:0 --time 0" + out), 0);
  EXPECT_FALSE(fs::exists(dir / "x.obj"));
}

// More than 4 influences: a real model with up to 6 per vertex (and weights summing to
// 0.94–1.38, normalized by default, refused with --strict-weights) skinned with 6 and with 4.
TEST_F(SkinCli, MaxInfluencesAndStrictWeights) {
  const std::string fbx = std::string(CONFORM_ASSIMP_MODELS) + "/FBX/animation_with_skeleton.fbx";
  EXPECT_NE(run(fbx + " --time 0.4 --strict-weights --out " + (dir / "r.obj").string()), 0);
  const auto model = io::import_model(fbx);
  skin::Pose pose;
  model.animations[0].sample(model.skeleton, 0.4, skin::Blend::log, pose);
  Eigen::Matrix3Xd four, six;
  for (int k : {4, 6}) {
    const fs::path out = dir / ("k" + std::to_string(k) + ".obj");
    ASSERT_EQ(
        run(fbx + " --time 0.4 --max-influences " + std::to_string(k) + " --out " + out.string()),
        0);
    skin::Skinner<double> s(model.skeleton, model.mesh.rest, model.influences, k);
    s.skin(pose, skin::SkinMode::cga);
    Eigen::Matrix3Xd expected;
    s.write(expected);
    const Eigen::Matrix3Xd got = read_obj_by_vertex(out, model.mesh);
    ASSERT_EQ(got.cols(), expected.cols());
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-9 * (1 + expected.cwiseAbs().maxCoeff()));
    (k == 4 ? four : six) = got;
  }
  EXPECT_GT((four - six).cwiseAbs().maxCoeff(), 1e-6);  // the 5th and 6th influences matter
}

}  // namespace
