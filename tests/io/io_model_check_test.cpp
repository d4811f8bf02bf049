// io::check_model (core/internal/conform/io/model_check.hpp): what the caller of an isolated
// import checks on the child's model. Real imports pass; each kind of damage a corrupted child
// could send is refused with its field named.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

#include "conform/io/import.hpp"
#include "conform/io/model_check.hpp"

using namespace conform;

namespace {

io::SkinnedModel arm() {
  return io::arm_model(1);
}

void expect_refused(const io::SkinnedModel& m, const std::string& words) {
  const std::string e = io::check_model(m);
  EXPECT_NE(e.find(words), std::string::npos) << "got: '" << e << "'";
}

TEST(IoModelCheck, RealModelsPass) {
  EXPECT_EQ(io::check_model(arm()), "");
  const std::filesystem::path models = CONFORM_ASSIMP_MODELS;
  for (const char* file : {"glTF2/simple_skin/simple_skin.gltf", "FBX/huesitos.fbx"}) {
    if (!std::filesystem::exists(models / file)) continue;
    for (const bool weld : {true, false}) {
      io::ImportOptions o;
      o.weld = weld;
      EXPECT_EQ(io::check_model(io::load_model((models / file).string(), o)), "") << file;
    }
  }
}

TEST(IoModelCheck, RefusesEachKindOfDamage) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  {
    auto m = arm();
    m.mesh.faces[7][1] = m.mesh.vertex_count() + 3;
    expect_refused(m, "mesh face 7 has vertex");
  }
  {
    auto m = arm();
    m.mesh.faces[2][2] = m.mesh.faces[2][0];
    expect_refused(m, "mesh face 2 repeats a vertex");
  }
  {
    auto m = arm();
    m.mesh.rest(1, 5) = kNaN;
    expect_refused(m, "NaN or infinite positions");
  }
  {
    auto m = arm();
    m.mesh.current.resize(3, m.mesh.vertex_count() - 1);
    expect_refused(m, "current positions are not one per vertex");
  }
  {
    auto m = arm();
    m.mesh.bones(0, 9) = 3;  // the arm has bones 0..2
    expect_refused(m, "mesh vertex 9 has influence (bone 3");
  }
  {
    auto m = arm();
    m.influences.offsets[1] = static_cast<std::int32_t>(m.influences.bones.size()) + 100;
    expect_refused(m, "influences: influence lists are inconsistent");
  }
  {
    auto m = arm();
    m.skeleton.joints[1].parent = 2;
    expect_refused(m, "skeleton: joint 1");
  }
  {
    auto m = arm();
    m.meshes[0].face_count += 1;
    expect_refused(m, "mesh entry 0 ('arm')");
  }
}

}  // namespace
