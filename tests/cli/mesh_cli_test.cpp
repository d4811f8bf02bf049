// The `conform cut|tear|drill` subcommands, run as a process (skipped when the command has
// not been built in this build tree).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>

#include "conform/io/import.hpp"

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

// Only the pieces, summary.json and the marker of a Conform result are written.
void expect_only_outputs(const fs::path& dir, int pieces, const std::string& ext) {
  int meshes = 0, others = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name == "summary.json" || name == ".conform-run") continue;
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

// --region-seed / --region-sphere (cut_region.hpp): huesitos.fbx's trunk and side branch are
// both crossed by this plane; limited to the branch, one loop is cut and two pieces written.
TEST_F(MeshCli, RegionalCutCutsOneSection) {
  const std::string model = std::string(CONFORM_ASSIMP_MODELS) + "/FBX/huesitos.fbx";
  if (!fs::exists(model)) GTEST_SKIP() << "assimp-testmodels not installed";
  const fs::path d = fresh_dir("region");
  const std::string plane = " --plane 0 1 -1 500 --cap --out " + d.string();
  ASSERT_EQ(run("cut " + model + plane), 0);
  EXPECT_EQ(summary(d)["output"]["pieces"], 3);
  fs::remove_all(d);
  ASSERT_EQ(run("cut " + model + plane + " --region-seed 400 300 -300"), 0);
  const auto s = summary(d);
  EXPECT_EQ(s["region"]["sections"], 2);
  EXPECT_EQ(s["region"]["kept_sections"], 1);
  EXPECT_EQ(s["output"]["pieces"], 2);
  EXPECT_EQ(s["output"]["closed"], true);
  fs::remove_all(d);
  // A sphere that holds no whole section: a documented no-op (exit 0, status missed).
  ASSERT_EQ(run("cut " + model + plane + " --region-sphere 400 300 -300 1"), 0);
  EXPECT_EQ(summary(d)["status"], "missed");
  fs::remove_all(d);
  EXPECT_NE(run("cut " + model + plane + " --region-sphere 0 0 0 -1"), 0);        // bad radius
  EXPECT_NE(run("cut arm --plane 0 0 1 0.3 --touching --out " + d.string()), 0);  // no sphere
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
  // --smooth-lips, as the scenes tear: one path point per sample, on the blade's track (0.1 m
  // long); the paper's path along edge crossings zigzags about it (0.1156 m, 73 points).
  const fs::path smooth = t / "smooth";
  ASSERT_EQ(run("tear arm --smooth-lips --scalpel " + (t / "scalpel.csv").string() +
                " --open 0.004 --out " + smooth.string()),
            0);
  const auto l = summary(smooth);
  EXPECT_EQ(l["smooth_lips"], true);
  EXPECT_EQ(l["tear"]["points"], 50);
  EXPECT_NEAR(l["tear"]["length"].get<double>(), 0.1, 0.001);
  EXPECT_GT(s["tear"]["length"].get<double>(), 0.11);
  EXPECT_EQ(l["output"]["manifold"], true);
  EXPECT_EQ(l["output"]["oriented"], true);
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

namespace {

// The vertices of a PLY or OBJ file as assimp reads them (the file's own numbering is lost; only
// positions matter here), and its area.
struct ReadMesh {
  std::vector<Eigen::Vector3d> points;
  double area = 0;
};

ReadMesh read_mesh(const fs::path& file) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), aiProcess_Triangulate);
  ReadMesh out;
  if (!scene) {
    ADD_FAILURE() << file << ": " << importer.GetErrorString();
    return out;
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto at = [&](unsigned i) {
      const aiVector3D& p = am->mVertices[i];
      return Eigen::Vector3d(p.x, p.y, p.z);
    };
    for (unsigned v = 0; v < am->mNumVertices; ++v) out.points.push_back(at(v));
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      out.area += 0.5 * (at(face.mIndices[1]) - at(face.mIndices[0]))
                            .cross(at(face.mIndices[2]) - at(face.mIndices[0]))
                            .norm();
    }
  }
  return out;
}

// −1, 0 or +1: which side of n·x = d all of `points` are on (0: on both sides).
int side(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& n, double d) {
  bool below = false, above = false;
  for (const auto& p : points) {
    below = below || n.dot(p) - d < -1e-6;
    above = above || n.dot(p) - d > 1e-6;
  }
  return below == above ? 0 : (above ? 1 : -1);
}

}  // namespace

// A posed edit: the cut is made on the model posed at --time, so the posed pieces lie
// on the two sides of the plane and add up to the posed model's area (written by `conform skin`
// at the same time); the rest pieces add up to the model's area at rest, and at rest the plane
// no longer separates them.
TEST_F(MeshCli, PosedCutCutsThePosedModelAndWritesTheRestPieces) {
  const std::string model = "/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf";
  const fs::path d = fresh_dir("posed");
  const Eigen::Vector3d n(0, 1, 0);
  const double at = 1.0;
  ASSERT_EQ(run("cut " + model + " --animation 0 --time 1.0 --plane 0 1 0 1.0 --out " + d.string()),
            0);
  const auto s = summary(d);
  EXPECT_EQ(s["pose"]["time_s"], 1.0);
  ASSERT_EQ(s["output"]["pieces"], 2);
  ASSERT_EQ(s["rest_pieces"].size(), 2u);
  double posed_area = 0, rest_area = 0;
  std::vector<int> posed_sides, rest_sides;
  for (const char* piece : {"piece_000.ply", "piece_001.ply"}) {
    const ReadMesh posed = read_mesh(d / piece), rest = read_mesh(d / "rest" / piece);
    EXPECT_EQ(posed.points.size(), rest.points.size()) << piece;
    posed_area += posed.area;
    rest_area += rest.area;
    posed_sides.push_back(side(posed.points, n, at));
    rest_sides.push_back(side(rest.points, n, at));
  }
  EXPECT_EQ(posed_sides[0] * posed_sides[1], -1) << "the posed pieces are not split by the plane";
  EXPECT_TRUE(rest_sides[0] == 0 || rest_sides[1] == 0) << "at rest the plane still separates";
  ASSERT_EQ(run("skin " + model + " --animation 0 --time 1.0 --out " + (d / "posed.ply").string()),
            0);
  EXPECT_NEAR(posed_area, read_mesh(d / "posed.ply").area, 1e-5);
  const auto m = conform::io::import_model(model);
  double model_rest_area = 0;
  for (const auto& t : m.mesh.faces)
    model_rest_area += 0.5 * (m.mesh.rest.col(t[1]) - m.mesh.rest.col(t[0]))
                                 .cross(m.mesh.rest.col(t[2]) - m.mesh.rest.col(t[0]))
                                 .norm();
  EXPECT_NEAR(rest_area, model_rest_area, 1e-5);
  // An unknown animation is refused, naming it.
  EXPECT_NE(run("cut " + model + " --animation walk --time 1 --plane 0 1 0 1 --out " + d.string()),
            0);
  fs::remove_all(d);
}
