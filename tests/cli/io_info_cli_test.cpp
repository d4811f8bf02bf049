// `conform info MODEL` prints meshes, counts, bones, the largest number of influences and the
// animations with their durations; `conform info` alone prints the version and features.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace {

const std::string kConform = std::string(CONFORM_BINARY_DIR) + "/scenes/conform";

std::string output(const std::string& args, int& rc) {
  std::string out;
  FILE* p = popen((kConform + " info " + args + " 2>&1").c_str(), "r");
  char buf[512];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  rc = p ? pclose(p) : -1;
  return out;
}

TEST(InfoCli, DescribesARealModel) {
  if (!std::filesystem::exists(kConform)) GTEST_SKIP() << "conform not built";
  int rc = 0;
  const std::string out = output(std::string(CONFORM_ASSIMP_MODELS) + "/FBX/huesitos.fbx", rc);
  EXPECT_EQ(rc, 0) << out;
  for (const char* s :
       // 128 vertices in the file, 62 welded at its seams (mesh_weld_test.cpp)
       {"meshes: 1", "\"Cylinder\": 62 vertices, 120 faces, 9 bones", "vertices: 62", "faces: 120",
        "bones: 9", "\"Bone.008\"", "largest number of influences per vertex: 4",
        "\"Armature|Action\": 1.56 s (39 ticks at 25 ticks/s)", "warning:"})
    EXPECT_NE(out.find(s), std::string::npos) << s << "\n" << out;
}

TEST(InfoCli, ArmAndVersion) {
  if (!std::filesystem::exists(kConform)) GTEST_SKIP() << "conform not built";
  int rc = 0;
  std::string out = output("arm:3", rc);
  EXPECT_EQ(rc, 0);
  EXPECT_NE(out.find("vertices: 23042"), std::string::npos) << out;
  EXPECT_NE(out.find("faces: 46080"), std::string::npos) << out;
  EXPECT_NE(out.find("animations: 0"), std::string::npos) << out;
  out = output("", rc);
  EXPECT_EQ(rc, 0);
  EXPECT_NE(out.find("conform "), std::string::npos);
  EXPECT_NE(out.find("Bullet precision"), std::string::npos) << out;
  out = output("/nonexistent/model.fbx", rc);
  EXPECT_NE(rc, 0);
  EXPECT_NE(out.find("/nonexistent/model.fbx: no such file"), std::string::npos) << out;
}

}  // namespace
