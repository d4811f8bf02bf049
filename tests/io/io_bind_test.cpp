// Exact bind transforms, weights and instances on the real models of Debian's
// assimp-testmodels, as imported: CGA skinning against matrix skinning computed from the
// file's raw (unprojected) matrices, within 1e-6 of the model's diagonal (float storage), at
// the rest pose and at key times of every animation.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

#include "assimp_reference.hpp"
#include "conform/io/import.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;

const std::string kModels = CONFORM_ASSIMP_MODELS;

// Every file under /usr/share/assimp/models that assimp 5.2 reads (with import_flags()) and
// whose meshes have at least one aiBone: found by reading all 453 files of the package (less
// kNoMeshFiles, whose only mesh assimp makes up itself). Among
// them FBX/animation_with_skeleton.fbx has a non-uniformly scaled mesh node (121 × 100 × 100)
// and offsets that carry it, and X/test_cube_*.x a mirroring root node and mirrored offsets.
// Vertex by vertex against the file's own meshes: the weld (on by default, checked in
// mesh_weld_test.cpp) would renumber them.
io::ImportOptions unwelded() {
  io::ImportOptions o;
  o.weld = false;
  return o;
}

const char* const kRiggedModels[] = {
    "BVH/01_01.bvh",
    "BVH/01_03.bvh",
    "BVH/Boxing_Toes.bvh",
    "Collada/box_nested_animation.dae",
    "FBX/animation_with_skeleton.fbx",
    "FBX/huesitos.fbx",
    "MD5/SimpleCube.md5mesh",
    "MDL/MDL (HL1)/alpha_test.mdl",
    "MDL/MDL (HL1)/blend_additive.mdl",
    "MDL/MDL (HL1)/chrome_sphere.mdl",
    "MDL/MDL (HL1)/duplicate_bodyparts.mdl",
    "MDL/MDL (HL1)/duplicate_sequence_groups/duplicate_sequence_groups.mdl",
    "MDL/MDL (HL1)/duplicate_sequences.mdl",
    "MDL/MDL (HL1)/duplicate_submodels.mdl",
    "MDL/MDL (HL1)/man.mdl",
    "MDL/MDL (HL1)/sequence_transitions.mdl",
    "MDL/MDL (HL1)/unnamed_bodyparts.mdl",
    "MDL/MDL (HL1)/unnamed_bones.mdl",
    "MDL/MDL (HL1)/unnamed_sequence_groups/unnamed_sequence_groups.mdl",
    "MDL/MDL (HL1)/unnamed_sequences.mdl",
    "SMD/WusonSMD.smd",
    "SMD/holy_grailref.smd",
    "SMD/triangle.smd",
    "X/BCN_Epileptic.X",
    "X/Testwuson.X",
    "X/anim_test.x",
    "X/test_cube_binary.x",
    "X/test_cube_compressed.x",
    "X/test_cube_text.x",
    "glTF2/simple_skin/simple_skin.gltf",
};

// Files assimp flags incomplete (AI_SCENE_FLAGS_INCOMPLETE): they hold no mesh (motion capture,
// cameras or lights only, or UTF-16 text assimp cannot read), and assimp adds a skeleton mesh of
// its own making, one bone per node, to show their node tree. Nothing to skin: refused, clearly.
const char* const kNoMeshFiles[] = {"ASE/ThreeCubesGreen_UTF16BE.ASE",
                                    "ASE/ThreeCubesGreen_UTF16LE.ASE", "CSM/ThomasFechten.csm",
                                    "Collada/cameras.dae", "Collada/lights.dae"};

struct Deviation {
  double diagonal = 0, bind = 0, poses = 0;
  int checked = 0;
};

// The largest |CGA − matrix skinning| at the rest pose and at up to `per_animation` key
// times of every animation (log and linear blends), with every influence of the file.
Deviation deviation(const io::SkinnedModel& model, const std::string& file, int per_animation) {
  test::Reference ref(file);
  EXPECT_NE(ref.scene, nullptr) << file;
  Deviation d;
  if (!ref.scene) return d;
  ref.project = false;
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences,
                                std::max(1, model.influences.max_per_vertex()));
  Eigen::Matrix3Xd got;
  skinner.skin(skin::Pose::rest(model.skeleton), skin::SkinMode::cga);
  skinner.write(got);
  const Eigen::Matrix3Xd bind = ref.lbs(-1, 0, true);
  EXPECT_EQ(bind.cols(), got.cols()) << file;
  if (bind.cols() != got.cols()) return d;
  d.diagonal = (bind.rowwise().maxCoeff() - bind.rowwise().minCoeff()).norm();
  d.bind = (got - bind).colwise().norm().maxCoeff();
  skin::Pose pose;
  for (int a = 0; a < static_cast<int>(model.animations.size()); ++a) {
    const auto& anim = model.animations[static_cast<std::size_t>(a)];
    const std::vector<double> keys = anim.key_times();
    const std::size_t stride = std::max<std::size_t>(1, keys.size() / per_animation);
    for (std::size_t i = 0; i < keys.size(); i += stride)
      for (const skin::Blend blend : {skin::Blend::log, skin::Blend::linear}) {
        anim.sample(model.skeleton, keys[i], blend, pose);
        skinner.skin(pose, skin::SkinMode::cga);
        skinner.write(got);
        d.poses = std::max(
            d.poses,
            (got - ref.lbs(a, keys[i], blend == skin::Blend::log)).colwise().norm().maxCoeff());
        ++d.checked;
      }
  }
  return d;
}

bool has_warning(const io::SkinnedModel& m, const std::string& text) {
  for (const auto& w : m.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

TEST(IoBind, EveryRiggedModelSkinsLikeMatrixSkinning) {
  int models = 0;
  for (const char* path : kRiggedModels) {
    const std::string file = kModels + "/" + path;
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    io::SkinnedModel model;
    try {
      model = io::import_model(file, unwelded());  // no file is refused
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    const Deviation d = deviation(model, file, 40);
    ASSERT_GT(d.diagonal, 0) << file;
    std::printf("%s: %d poses, diag %.4g, |CGA − matrix| / diag: bind %.3g, poses %.3g\n", path,
                d.checked, d.diagonal, d.bind / d.diagonal, d.poses / d.diagonal);
    EXPECT_LT(d.bind, 1e-6 * d.diagonal) << file;
    EXPECT_LT(d.poses, 1e-6 * d.diagonal) << file;
    EXPECT_FALSE(has_warning(model, "deviates from matrix skinning")) << file;
    ++models;
  }
  EXPECT_EQ(models, 30);
  for (const char* path : kNoMeshFiles) {
    try {
      io::import_model(kModels + "/" + path);
      ADD_FAILURE() << path;
    } catch (const io::ImportError& e) {
      EXPECT_NE(std::string(e.what()).find("incomplete scene"), std::string::npos) << e.what();
    }
  }
}

// The mirrored and the non-uniformly scaled ones by name: the mirror is carried as the odd
// parity of the subtree (X/test_cube_text.x), the stretch baked into the rest positions
// (FBX/animation_with_skeleton.fbx, whose animation moves 14 bones under the stretched node).
TEST(IoBind, MirroredAndStretchedRealModelsAreExact) {
  for (const char* path : {"X/test_cube_text.x", "FBX/animation_with_skeleton.fbx"}) {
    const std::string file = kModels + "/" + path;
    const io::SkinnedModel model = io::import_model(file, unwelded());
    const Deviation d = deviation(model, file, 1000);
    EXPECT_LT(d.bind, 1e-6 * d.diagonal) << path;
    EXPECT_LT(d.poses, 1e-6 * d.diagonal) << path;
    EXPECT_FALSE(has_warning(model, "mirror")) << path;
    EXPECT_FALSE(has_warning(model, "non-uniform")) << path;
  }
}

// A column-convention 4×4 matrix as an .x file's row-vector FrameTransformMatrix.
std::string x_matrix(const Eigen::Matrix4d& m) {
  std::ostringstream os;
  os << std::fixed;
  os.precision(17);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) os << m(c, r) << (r == 3 && c == 3 ? ";;" : ",");
  return os.str();
}

Eigen::Matrix4d trs(const Eigen::Vector3d& t, const Eigen::Matrix3d& a) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = a;
  m.topRightCorner<3, 1>() = t;
  return m;
}

// A two-bone box under a mirroring root, its mesh node scaled non-uniformly (2, 1, 0.5), the
// offsets consistent (O = G⁻¹ M), the second bone rotating (and, with `stretch`, scaling
// non-uniformly) in its animation. Written at test time.
std::string write_x(const std::string& name, bool stretch) {
  const Eigen::Matrix4d root = trs({0.5, 0, 0}, Eigen::Vector3d(-1, 1, 1).asDiagonal());
  const Eigen::Matrix4d arm =
      trs({0, 1, 0}, Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  const Eigen::Matrix4d fore = trs({0, 2, 0}, 1.5 * Eigen::Matrix3d::Identity());
  const Eigen::Matrix4d body = trs({0.2, 0, 0.1}, Eigen::Vector3d(2, 1, 0.5).asDiagonal());
  const Eigen::Matrix4d mesh = root * body;
  const Eigen::Matrix4d offset1 = (root * arm).inverse() * mesh,
                        offset2 = (root * arm * fore).inverse() * mesh;
  std::ostringstream x;
  x << std::fixed;
  x.precision(17);
  x << "xof 0303txt 0032\nFrame Root {\n FrameTransformMatrix { " << x_matrix(root) << " }\n"
    << " Frame Arm {\n  FrameTransformMatrix { " << x_matrix(arm) << " }\n"
    << "  Frame Fore {\n   FrameTransformMatrix { " << x_matrix(fore) << " }\n  }\n }\n"
    << " Frame Body {\n  FrameTransformMatrix { " << x_matrix(body) << " }\n"
    << "  Mesh Box {\n   8;\n";
  for (int v = 0; v < 8; ++v)
    x << "   " << (v & 1 ? 1.0 : -1.0) << ";" << (v & 2 ? 3.0 : -1.0) << ";" << (v & 4 ? 1.0 : -1.0)
      << ";" << (v == 7 ? ";\n" : ",\n");
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  x << "   12;\n";
  for (int q = 0; q < 6; ++q) {
    const int* f = quads[q];
    x << "   3;" << f[0] << "," << f[1] << "," << f[2] << ";,\n   3;" << f[0] << "," << f[2] << ","
      << f[3] << (q == 5 ? ";;\n" : ";,\n");
  }
  x << "   XSkinMeshHeader { 2; 2; 2; }\n";
  for (int b = 0; b < 2; ++b) {
    x << "   SkinWeights {\n    \"" << (b ? "Fore" : "Arm") << "\";\n    8;\n";
    for (int v = 0; v < 8; ++v) x << "    " << v << (v == 7 ? ";\n" : ",\n");
    for (int v = 0; v < 8; ++v) {
      const double up = (v & 2) ? 0.8 : 0.1;  // the top follows Fore
      x << "    " << (b ? up : 1 - up) << (v == 7 ? ";\n" : ",\n");
    }
    x << "    " << x_matrix(b ? offset2 : offset1) << "\n   }\n";
  }
  x << "  }\n }\n}\nAnimationSet Bend {\n Animation {\n  { Fore }\n  AnimationKey {\n   0;\n"
    << "   2;\n   0;4;1.0,0.0,0.0,0.0;;,\n   10;4;0.921060994,0.389418342,0.0,0.0;;;\n  }\n";
  if (stretch)
    x << "  AnimationKey {\n   1;\n   2;\n   0;3;1.5,1.5,1.5;;,\n   10;3;1.5,3.0,1.5;;;\n  }\n";
  x << " }\n}\n";
  const std::string file = testing::TempDir() + name;
  std::ofstream(file) << x.str();
  return file;
}

TEST(IoBind, WrittenMirroredAndStretchedFileIsExact) {
  const std::string file = write_x("conform_mirror_stretch.x", false);
  const io::SkinnedModel model = io::import_model(file, unwelded());
  ASSERT_EQ(model.animations.size(), 1u);
  const Deviation d = deviation(model, file, 1000);
  EXPECT_GT(d.checked, 0);
  EXPECT_LT(d.bind, 1e-6 * d.diagonal);  // assimp reads .x files in float
  EXPECT_LT(d.poses, 1e-6 * d.diagonal);
  EXPECT_FALSE(has_warning(model, "deviates from matrix skinning"));
  // The mesh keeps facing outwards: rewound where the baked part mirrors.
  EXPECT_EQ(model.mesh.face_count(), 12);
}

// A bone whose animation really scales it non-uniformly cannot be a versor: the import says so
// and quantifies the deviation from matrix skinning relative to the diagonal.
TEST(IoBind, AnimatedNonUniformScaleIsReportedWithItsError) {
  const std::string file = write_x("conform_animated_stretch.x", true);
  const io::SkinnedModel model = io::import_model(file, unwelded());
  std::string warning;
  for (const auto& w : model.warnings)
    if (w.find("deviates from matrix skinning") != std::string::npos) warning = w;
  ASSERT_FALSE(warning.empty());
  EXPECT_NE(warning.find("Fore"), std::string::npos) << warning;
  EXPECT_NE(warning.find("of the model's diagonal"), std::string::npos) << warning;
  EXPECT_NE(warning.find("animation 'Bend'"), std::string::npos) << warning;
  // The quoted figure is a real deviation (the top's y doubles between mean and true scale).
  const auto at = warning.find("by up to ") + 9;
  EXPECT_GT(std::stod(warning.substr(at)), 1e-2) << warning;
}

// Weights off 1 (a Blender export: 0.94–1.38): normalized with one summary warning by
// default, refused with strict_weights.
TEST(IoBind, WeightsAreNormalizedByDefaultAndRefusedWhenStrict) {
  const std::string file = kModels + "/FBX/animation_with_skeleton.fbx";
  const io::SkinnedModel model = io::import_model(file, unwelded());
  int warnings = 0;
  for (const auto& w : model.warnings) warnings += w.find("do not sum to 1") != std::string::npos;
  EXPECT_EQ(warnings, 1);
  for (Eigen::Index v = 0; v < model.mesh.vertex_count(); ++v) {
    double sum = 0;
    for (auto k = model.influences.offsets[static_cast<std::size_t>(v)];
         k < model.influences.offsets[static_cast<std::size_t>(v) + 1]; ++k)
      sum += model.influences.weights[static_cast<std::size_t>(k)];
    ASSERT_NEAR(sum, 1, 1e-12) << v;
  }
  io::ImportOptions strict;
  strict.strict_weights = true;
  try {
    io::import_model(file, strict);
    ADD_FAILURE() << "strict weights accepted sums of 0.94–1.38";
  } catch (const io::ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("strict weights"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(io::import_model(kModels + "/glTF2/simple_skin/simple_skin.gltf", strict));
}

// A mesh placed by several nodes yields every instance, each where its node puts it.
TEST(IoBind, InstancedMeshYieldsAllItsInstances) {
  for (const char* path : {"glTF/TwoBoxes/TwoBoxes.gltf", "Collada/teapot_instancenodes.DAE",
                           "glTF/CesiumMilkTruck/CesiumMilkTruck.gltf",
                           "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}) {
    const std::string file = kModels + "/" + path;
    const io::SkinnedModel model = io::import_model(file, unwelded());
    test::Reference ref(file);
    ASSERT_NE(ref.scene, nullptr) << path;
    const auto placed = ref.placements();
    EXPECT_GT(placed.size(), ref.scene->mNumMeshes) << path;  // some mesh is instanced
    ASSERT_EQ(model.meshes.size(), placed.size()) << path;
    std::int32_t vertices = 0;
    for (std::size_t i = 0; i < placed.size(); ++i) {
      EXPECT_EQ(model.meshes[i].source, static_cast<std::int32_t>(placed[i].first)) << path;
      EXPECT_EQ(model.meshes[i].first_vertex, vertices) << path;
      vertices += static_cast<std::int32_t>(ref.scene->mMeshes[placed[i].first]->mNumVertices);
    }
    EXPECT_EQ(model.mesh.vertex_count(), vertices) << path;
    ref.project = false;
    const Eigen::Matrix3Xd expected = ref.lbs(-1, 0, true);
    const double diag = (expected.rowwise().maxCoeff() - expected.rowwise().minCoeff()).norm();
    EXPECT_LT((model.mesh.current - expected).colwise().norm().maxCoeff(), 1e-6 * diag) << path;
  }
}

}  // namespace

namespace {

std::array<double, 9> coefficients(const skin::Versor& v) {
  const auto& m = v.motor;
  return {m.s, m.e12, m.e13, m.e23, m.e1inf, m.e2inf, m.e3inf, m.e123inf, v.scale};
}

// Field by field, bit for bit: the isolated import ran the same code in the child.
void expect_same_model(const io::SkinnedModel& a, const io::SkinnedModel& b, const char* path) {
  SCOPED_TRACE(path);
  EXPECT_EQ(a.source, b.source);
  const auto& m = a.mesh;
  const auto& n = b.mesh;
  EXPECT_EQ(m.rest, n.rest);
  EXPECT_EQ(m.current, n.current);
  EXPECT_EQ(m.faces, n.faces);
  EXPECT_EQ(m.bones, n.bones);
  EXPECT_EQ(m.weights, n.weights);
  EXPECT_EQ(m.uvs, n.uvs);
  EXPECT_EQ(m.normals, n.normals);
  EXPECT_EQ(m.corner_uvs, n.corner_uvs);
  EXPECT_EQ(m.corner_normals, n.corner_normals);
  EXPECT_EQ(a.influences.offsets, b.influences.offsets);
  EXPECT_EQ(a.influences.bones, b.influences.bones);
  EXPECT_EQ(a.influences.weights, b.influences.weights);
  ASSERT_EQ(a.skeleton.joint_count(), b.skeleton.joint_count());
  for (std::size_t j = 0; j < a.skeleton.joints.size(); ++j) {
    EXPECT_EQ(a.skeleton.joints[j].name, b.skeleton.joints[j].name);
    EXPECT_EQ(a.skeleton.joints[j].parent, b.skeleton.joints[j].parent);
    EXPECT_EQ(coefficients(a.skeleton.joints[j].rest), coefficients(b.skeleton.joints[j].rest));
  }
  ASSERT_EQ(a.skeleton.bone_count(), b.skeleton.bone_count());
  for (std::size_t i = 0; i < a.skeleton.bones.size(); ++i) {
    EXPECT_EQ(a.skeleton.bones[i].name, b.skeleton.bones[i].name);
    EXPECT_EQ(a.skeleton.bones[i].joint, b.skeleton.bones[i].joint);
    EXPECT_EQ(coefficients(a.skeleton.bones[i].offset), coefficients(b.skeleton.bones[i].offset));
  }
  ASSERT_EQ(a.animations.size(), b.animations.size());
  for (std::size_t i = 0; i < a.animations.size(); ++i) {
    const auto &x = a.animations[i], &y = b.animations[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.duration_ticks, y.duration_ticks);
    EXPECT_EQ(x.ticks_per_second, y.ticks_per_second);
    ASSERT_EQ(x.channels.size(), y.channels.size());
    for (std::size_t c = 0; c < x.channels.size(); ++c) {
      const auto &p = x.channels[c], &q = y.channels[c];
      EXPECT_EQ(p.joint, q.joint);
      ASSERT_EQ(p.translation.size(), q.translation.size());
      ASSERT_EQ(p.rotation.size(), q.rotation.size());
      ASSERT_EQ(p.scale.size(), q.scale.size());
      for (std::size_t k = 0; k < p.translation.size(); ++k) {
        EXPECT_EQ(p.translation[k].time, q.translation[k].time);
        EXPECT_EQ(p.translation[k].value, q.translation[k].value);
      }
      for (std::size_t k = 0; k < p.rotation.size(); ++k) {
        EXPECT_EQ(p.rotation[k].time, q.rotation[k].time);
        EXPECT_EQ(p.rotation[k].value.coeffs(), q.rotation[k].value.coeffs());
      }
      for (std::size_t k = 0; k < p.scale.size(); ++k) {
        EXPECT_EQ(p.scale[k].time, q.scale[k].time);
        EXPECT_EQ(p.scale[k].value, q.scale[k].value);
      }
    }
  }
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t i = 0; i < a.meshes.size(); ++i) {
    const auto &x = a.meshes[i], &y = b.meshes[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(std::tie(x.first_vertex, x.vertex_count, x.first_face, x.face_count, x.joint, x.bones,
                       x.source),
              std::tie(y.first_vertex, y.vertex_count, y.first_face, y.face_count, y.joint, y.bones,
                       y.source));
  }
  EXPECT_EQ(a.warnings, b.warnings);
}

}  // namespace

// An isolated import (ImportOptions::isolate: the child imports, the caller decodes) gives the
// same model as one in this process, on every rigged test model, welded (UV and normal corner
// arrays) and not.
TEST(IoBind, IsolatedImportIsTheSameModel) {
  for (const char* path : kRiggedModels) {
    const std::string file = kModels + "/" + path;
    for (const bool weld : {true, false}) {
      io::ImportOptions here;
      here.weld = weld;
      io::ImportOptions isolated = here;
      isolated.isolate = true;
      expect_same_model(io::import_model(file, here), io::import_model(file, isolated), path);
    }
  }
}
