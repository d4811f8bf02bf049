// Import of real rigged models (Debian's assimp-testmodels) and the correctness of the whole
// skinning path against matrix LBS computed independently from assimp's own aiMatrix4x4 node
// and offset matrices, in double, at every key time of every animation.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>

#include "conform/io/import.hpp"
#include "conform/skin/baselines.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;
using M4 = aiMatrix4x4t<double>;

const std::string kModels = CONFORM_ASSIMP_MODELS;

M4 to_double(const aiMatrix4x4& m) {
  M4 r;
  for (unsigned i = 0; i < 4; ++i)
    for (unsigned j = 0; j < 4; ++j) r[i][j] = m[i][j];
  return r;
}

// The nearest similarity s R | t to an affine matrix (R the polar factor, s the mean singular
// value). The files store float matrices whose rotation blocks are orthonormal only to ~1e-7,
// and a versor is an exact similarity; `project` makes the reference use exact similarities
// too, so that what is compared is the algebra, not float noise in the files. The raw
// matrices are checked as well, to a tolerance that float storage allows.
M4 similar(const M4& m) {
  Eigen::Matrix3d a;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) a(i, j) = m[i][j];
  // Newton's polar iteration R ← ½ (R + R⁻ᵀ) (quadratic convergence from near-orthogonal);
  // the mean singular value is trace(Rᵀ A) / 3.
  Eigen::Matrix3d q = a;
  for (int i = 0; i < 30; ++i) q = 0.5 * (q + q.inverse().transpose());
  const Eigen::Matrix3d r = (q.transpose() * a).trace() / 3 * q;
  M4 out = m;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) out[i][j] = r(i, j);
  return out;
}

// Interpolation of one key track at `ticks`, written out here (not the library's blends):
// positions lerp, rotations slerp (log) or sign-aligned normalized lerp (linear), scales
// geometric (log) or linear. Outside the keys the end keys hold.
template <class Key, class F>
auto track(const Key* keys, unsigned n, double ticks, F interpolate) {
  using V = decltype(interpolate(keys[0].mValue, keys[0].mValue, 0.0));
  if (ticks <= keys[0].mTime) return interpolate(keys[0].mValue, keys[0].mValue, 0.0);
  if (ticks >= keys[n - 1].mTime) return interpolate(keys[n - 1].mValue, keys[n - 1].mValue, 0.0);
  unsigned i = 0;
  while (keys[i + 1].mTime <= ticks) ++i;
  const double a = (ticks - keys[i].mTime) / (keys[i + 1].mTime - keys[i].mTime);
  return V(interpolate(keys[i].mValue, keys[i + 1].mValue, a));
}

aiQuaterniont<double> quat_interp(const aiQuaternion& qa, const aiQuaternion& qb, double a,
                                  bool slerp) {
  double w0 = qa.w, x0 = qa.x, y0 = qa.y, z0 = qa.z, w1 = qb.w, x1 = qb.x, y1 = qb.y, z1 = qb.z;
  const double n0 = std::sqrt(w0 * w0 + x0 * x0 + y0 * y0 + z0 * z0),
               n1 = std::sqrt(w1 * w1 + x1 * x1 + y1 * y1 + z1 * z1);
  w0 /= n0, x0 /= n0, y0 /= n0, z0 /= n0, w1 /= n1, x1 /= n1, y1 /= n1, z1 /= n1;
  double c = w0 * w1 + x0 * x1 + y0 * y1 + z0 * z1;
  if (c < 0) c = -c, w1 = -w1, x1 = -x1, y1 = -y1, z1 = -z1;
  double k0 = 1 - a, k1 = a;
  if (slerp && a != 0 && c < 1) {
    const double th = std::acos(std::min(1.0, c)), s = std::sin(th);
    if (s > 1e-300) k0 = std::sin((1 - a) * th) / s, k1 = std::sin(a * th) / s;
  }
  double w = k0 * w0 + k1 * w1, x = k0 * x0 + k1 * x1, y = k0 * y0 + k1 * y1, z = k0 * z0 + k1 * z1;
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  return aiQuaterniont<double>(w / n, x / n, y / n, z / n);
}

struct Reference {
  bool project = true;  // see similar()
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  std::map<std::string, const aiNode*> nodes;

  explicit Reference(const std::string& file) {
    scene = importer.ReadFile(file, io::import_flags());
    if (!scene) return;
    std::function<void(const aiNode*)> walk = [&](const aiNode* n) {
      nodes.emplace(n->mName.C_Str(), n);
      for (unsigned c = 0; c < n->mNumChildren; ++c) walk(n->mChildren[c]);
    };
    walk(scene->mRootNode);
  }

  // Local matrix of a node at `seconds` of animation `anim` (−1: the node's own transform):
  // T · R · S from the channel's keys, the node's own transform when it has no channel.
  M4 local(const aiNode* n, int anim, double seconds, bool log) const {
    if (anim >= 0) {
      const aiAnimation* a = scene->mAnimations[anim];
      const double tps = a->mTicksPerSecond != 0 ? a->mTicksPerSecond : 25.0;
      const double ticks = seconds * tps;
      for (unsigned c = 0; c < a->mNumChannels; ++c) {
        const aiNodeAnim* ch = a->mChannels[c];
        if (ch->mNodeName != n->mName) continue;
        // A channel always has keys of each kind in these files.
        const auto p =
            track(ch->mPositionKeys, ch->mNumPositionKeys, ticks,
                  [](const aiVector3D& u, const aiVector3D& v, double t) {
                    return aiVector3t<double>((1 - t) * u.x + t * v.x, (1 - t) * u.y + t * v.y,
                                              (1 - t) * u.z + t * v.z);
                  });
        const auto q = track(ch->mRotationKeys, ch->mNumRotationKeys, ticks,
                             [log](const aiQuaternion& u, const aiQuaternion& v, double t) {
                               return quat_interp(u, v, t, log);
                             });
        const double s = track(ch->mScalingKeys, ch->mNumScalingKeys, ticks,
                               [log](const aiVector3D& u, const aiVector3D& v, double t) {
                                 const double su = (double(u.x) + u.y + u.z) / 3,
                                              sv = (double(v.x) + v.y + v.z) / 3;
                                 return log ? std::exp((1 - t) * std::log(su) + t * std::log(sv))
                                            : (1 - t) * su + t * sv;
                               });
        return M4(aiVector3t<double>(s, s, s), q, p);
      }
    }
    return project ? similar(to_double(n->mTransformation)) : to_double(n->mTransformation);
  }

  M4 global(const aiNode* n, int anim, double seconds, bool log) const {
    M4 g = local(n, anim, seconds, log);
    for (const aiNode* p = n->mParent; p; p = p->mParent) g = local(p, anim, seconds, log) * g;
    return g;
  }

  // Matrix LBS, x' = Σ w_b (G_b O_b) x with the file's weights normalized per vertex; a bone
  // without a node stays at its bind pose (G_b O_b = identity); a mesh without bones follows
  // its node. Also returns the per-vertex skinning matrices' dual-quaternion blend.
  Eigen::Matrix3Xd lbs(int anim, double seconds, bool log,
                       Eigen::Matrix3Xd* dq_out = nullptr) const {
    std::size_t nv = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) nv += scene->mMeshes[m]->mNumVertices;
    Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(nv));
    std::vector<Eigen::Matrix4d> mats;
    skin::InfluenceLists lists;
    std::vector<std::vector<std::pair<int, double>>> inf(nv);
    std::size_t base = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* am = scene->mMeshes[m];
      if (am->mNumBones == 0) {
        const aiNode* owner = nullptr;
        std::function<void(const aiNode*)> find = [&](const aiNode* n) {
          for (unsigned i = 0; i < n->mNumMeshes && !owner; ++i)
            if (n->mMeshes[i] == m) owner = n;
          for (unsigned c = 0; c < n->mNumChildren && !owner; ++c) find(n->mChildren[c]);
        };
        find(scene->mRootNode);
        const M4 g = global(owner, anim, seconds, log);
        mats.push_back(Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(&g.a1));
        for (unsigned v = 0; v < am->mNumVertices; ++v)
          inf[base + v].push_back({int(mats.size() - 1), 1.0});
      }
      for (unsigned b = 0; b < am->mNumBones; ++b) {
        const aiBone* bone = am->mBones[b];
        const auto it = nodes.find(bone->mName.C_Str());
        const M4 offset =
            project ? similar(to_double(bone->mOffsetMatrix)) : to_double(bone->mOffsetMatrix);
        const M4 skin = it == nodes.end() ? M4() : global(it->second, anim, seconds, log) * offset;
        mats.push_back(Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(&skin.a1));
        for (unsigned k = 0; k < bone->mNumWeights; ++k)
          if (bone->mWeights[k].mWeight > 0)
            inf[base + bone->mWeights[k].mVertexId].push_back(
                {int(mats.size() - 1), bone->mWeights[k].mWeight});
      }
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        double sum = 0;
        for (auto& [i, w] : inf[base + v]) sum += w;
        Eigen::Vector4d x(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z, 1);
        Eigen::Vector4d acc = Eigen::Vector4d::Zero();
        for (auto& [i, w] : inf[base + v])
          acc += (w / sum) * (mats[static_cast<std::size_t>(i)] * x);
        out.col(static_cast<Eigen::Index>(base + v)) = acc.head<3>();
        for (auto& [i, w] : inf[base + v]) {
          lists.bones.push_back(i);
          lists.weights.push_back(w / sum);
        }
        lists.offsets.push_back(static_cast<std::int32_t>(lists.bones.size()));
      }
      base += am->mNumVertices;
    }
    if (dq_out) {
      // Dual-quaternion skinning of the same matrices (the baseline job), for the versor mode.
      std::vector<skin::DqBone<double>> dq(mats.size());
      skin::dq_bones<double>(mats, dq);
      Eigen::Matrix3Xd rest(3, static_cast<Eigen::Index>(nv));
      base = 0;
      for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        for (unsigned v = 0; v < scene->mMeshes[m]->mNumVertices; ++v, ++base) {
          const auto& p = scene->mMeshes[m]->mVertices[v];
          rest.col(static_cast<Eigen::Index>(base)) = Eigen::Vector3d(p.x, p.y, p.z);
        }
      const auto soa = skin::SoaPoints<double>::from(rest);
      const auto infl = skin::Influences<double>::select(lists, lists.max_per_vertex());
      skin::SoaPoints<double> o;
      o.resize(nv);
      skin::DqSkinningJob<double> job{
          dq, {soa.x, soa.y, soa.z, infl.count, infl.bones, infl.weights}, {o.x, o.y, o.z}, 1};
      EXPECT_EQ(job.validate(), "");
      job.run();
      o.to(*dq_out);
    }
    return out;
  }
};

struct Case {
  const char* path;
  int bones, animations, vertices;
  double weight_tolerance = 0.1;  // ImportOptions
  int influences = 4;             // the file's largest number per vertex: all are used
  bool nonuniform = false;        // has non-uniform scales: no versor equals its raw matrices
};

class RealModel : public testing::TestWithParam<Case> {};

TEST_P(RealModel, CgaSkinningEqualsAssimpMatrixLbsAtEveryKey) {
  const Case c = GetParam();
  const std::string file = kModels + "/" + c.path;
  io::ImportOptions options;
  options.weight_tolerance = c.weight_tolerance;
  options.weld = false;  // vertex by vertex against assimp's; welded: mesh_weld_test.cpp
  const io::SkinnedModel model = io::import_model(file, options);
  EXPECT_EQ(model.influences.max_per_vertex(), c.influences);
  Reference ref(file);
  ASSERT_NE(ref.scene, nullptr);
  EXPECT_EQ(model.skeleton.bone_count(), c.bones);
  EXPECT_EQ(static_cast<int>(model.animations.size()), c.animations);
  EXPECT_EQ(model.mesh.vertex_count(), c.vertices);

  // Bind pose first. `current` is the skinned bind pose in world space, with the shared
  // mesh's 4 influences; the skinner uses all of the file's.
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences, c.influences);
  skinner.skin(skin::Pose::rest(model.skeleton), skin::SkinMode::cga);
  Eigen::Matrix3Xd rest_pose;
  skinner.write(rest_pose);
  const Eigen::Matrix3Xd bind = ref.lbs(-1, 0, true);
  const double diag = (bind.rowwise().maxCoeff() - bind.rowwise().minCoeff()).norm();
  ASSERT_GT(diag, 0);
  const double tol = 1e-9 * diag;
  EXPECT_LT((rest_pose - bind).colwise().norm().maxCoeff(), tol);
  if (c.influences <= 4) {
    EXPECT_LT((model.mesh.current - bind).colwise().norm().maxCoeff(), tol);
  }

  // Against the raw float matrices of the file: equal to float precision.
  ref.project = false;
  const Eigen::Matrix3Xd raw_bind = ref.lbs(-1, 0, true);
  const double raw = (rest_pose - raw_bind).colwise().norm().maxCoeff() / diag;
  if (!c.nonuniform) {
    EXPECT_LT(raw, 1e-6);
  }
  bool warned = false;
  for (const auto& w : model.warnings)
    warned = warned || w.find("non-uniform") != std::string::npos;
  EXPECT_EQ(warned, c.nonuniform);
  ref.project = true;

  skin::Pose pose;
  int checked = 0;
  double worst_lbs = 0, worst_dq = 0, moved = 0, worst_raw = 0;
  for (int a = 0; a < static_cast<int>(model.animations.size()); ++a) {
    const auto& anim = model.animations[static_cast<std::size_t>(a)];
    std::vector<double> times = anim.key_times();
    // and some times between keys
    for (std::size_t i = 0; i + 1 < anim.key_times().size(); i += 3)
      times.push_back(0.37 * anim.key_times()[i] + 0.63 * anim.key_times()[i + 1]);
    for (const skin::Blend blend : {skin::Blend::log, skin::Blend::linear}) {
      const bool log = blend == skin::Blend::log;
      for (const double t : times) {
        anim.sample(model.skeleton, t, blend, pose);
        Eigen::Matrix3Xd dq;
        const Eigen::Matrix3Xd expected = ref.lbs(a, t, log, &dq);
        Eigen::Matrix3Xd got;
        skinner.skin(pose, skin::SkinMode::cga);
        skinner.write(got);
        worst_lbs = std::max(worst_lbs, (got - expected).colwise().norm().maxCoeff());
        skinner.skin(pose, skin::SkinMode::versor);
        skinner.write(got);
        worst_dq = std::max(worst_dq, (got - dq).colwise().norm().maxCoeff());
        moved = std::max(moved, (expected - bind).colwise().norm().maxCoeff());
        ref.project = false;
        skinner.skin(pose, skin::SkinMode::cga);
        skinner.write(got);
        worst_raw = std::max(worst_raw, (got - ref.lbs(a, t, log)).colwise().norm().maxCoeff());
        ref.project = true;
        ++checked;
      }
    }
  }
  RecordProperty("worst_lbs_over_diag", std::to_string(worst_lbs / diag));
  std::printf(
      "%s: %d poses, diag %.4g, worst |CGA − LBS| / diag = %.3g, |versor − DQ| / diag = %.3g; "
      "vs unprojected float matrices: bind %.3g, poses %.3g\n",
      c.path, checked, diag, worst_lbs / diag, worst_dq / diag, raw, worst_raw / diag);
  if (!c.nonuniform) {
    EXPECT_LT(worst_raw, 1e-6 * diag);
  }
  EXPECT_LT(worst_lbs, tol);
  EXPECT_LT(worst_dq, tol);
  if (c.animations > 0) {
    EXPECT_GT(checked, 0);
    EXPECT_GT(moved, 1e-3 * diag);  // the animation really moves the mesh
  }
}

INSTANTIATE_TEST_SUITE_P(
    AssimpTestModels, RealModel,
    testing::Values(Case{"glTF2/simple_skin/simple_skin.gltf", 2, 1, 10, 0.1, 2},
                    Case{"FBX/huesitos.fbx", 9, 1, 128}, Case{"X/anim_test.x", 4, 1, 485},
                    // weights summing to 0.94–1.38, up to 6 per vertex
                    // and non-uniform node and offset scales (mean scale used, warned)
                    Case{"FBX/animation_with_skeleton.fbx", 14, 1, 2464, 0.5, 6, true}),
    [](const auto& info) {
      std::string n = info.param.path;
      n = n.substr(n.rfind('/') + 1);
      for (auto& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(IoImport, ModelStructure) {
  const auto m = io::import_model(kModels + "/FBX/huesitos.fbx");
  EXPECT_EQ(m.influences.max_per_vertex(), 4);
  EXPECT_EQ(m.meshes.size(), 1u);
  EXPECT_EQ(m.skeleton.validate(), "");
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].ticks_per_second, 25);
  EXPECT_NEAR(m.animations[0].duration(), 39.0 / 25, 1e-12);
  EXPECT_EQ(m.find_animation("Armature|Action"), 0);
  EXPECT_EQ(m.find_animation("0"), 0);
  EXPECT_EQ(m.find_animation("1"), -1);
  EXPECT_GE(m.skeleton.find_joint("Bone.008"), 0);
  // The mesh keeps the 4 largest influences; weights sorted and summing to 1.
  for (int v = 0; v < m.mesh.vertex_count(); ++v) {
    EXPECT_NEAR(m.mesh.weights.col(v).sum(), 1.0, 1e-12);
    for (int k = 0; k + 1 < 4; ++k) EXPECT_GE(m.mesh.weights(k, v), m.mesh.weights(k + 1, v));
  }
  // Warned about the unnormalized weights of the file (sums 0.948 … 1).
  bool warned = false;
  for (const auto& w : m.warnings) warned = warned || w.find("renormalized") != std::string::npos;
  EXPECT_TRUE(warned);

  const auto x = io::import_model(kModels + "/X/anim_test.x");
  EXPECT_EQ(x.animations[0].ticks_per_second, 24);
  EXPECT_GE(x.skeleton.find_joint("joint3"), 0);  // bone without a node: a joint of its own
}

// A model without bones is one rigid bone per mesh node and follows its node.
TEST(IoImport, MeshWithoutBonesIsOneRigidBone) {
  const std::string file = kModels + "/OBJ/box.obj";
  io::ImportOptions unwelded;
  unwelded.weld = false;  // vertex by vertex against assimp's
  const auto m = io::import_model(file, unwelded);
  EXPECT_EQ(m.animations.size(), 0u);
  EXPECT_GE(m.skeleton.bone_count(), 1);
  EXPECT_EQ(m.influences.max_per_vertex(), 1);
  Reference ref(file);
  const Eigen::Matrix3Xd bind = ref.lbs(-1, 0, true);
  EXPECT_LT((m.mesh.current - bind).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(IoImport, ArmSpecs) {
  const auto a = io::load_model("arm");
  EXPECT_EQ(a.mesh.vertex_count(), 2562);
  EXPECT_EQ(a.source, "arm:1");
  EXPECT_EQ(io::load_model("arm:2").mesh.face_count(), 4 * 5120);
  for (const char* bad : {"arm:", "arm:0", "arm:x", "arm:2x", "arm:-1"}) {
    try {
      io::load_model(bad);
      ADD_FAILURE() << bad;
    } catch (const io::ImportError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos);
    }
  }
}

// A file that gives no ticks per second (assimp reports 0) plays at 25 ticks/s; the animated
// bone moves its vertices. Written at test time: a one-triangle X file with one bone.
TEST(IoImport, ZeroTicksPerSecondMeans25) {
  const std::string x = R"(xof 0303txt 0032
Frame Root {
  FrameTransformMatrix {
    1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
  }
  Frame Bone1 {
    FrameTransformMatrix {
      1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
    }
  }
  Mesh Tri {
    3;
    0.0;0.0;0.0;,
    1.0;0.0;0.0;,
    0.0;1.0;0.0;;
    1;
    3;0,1,2;;
    XSkinMeshHeader {
      1;
      1;
      1;
    }
    SkinWeights {
      "Bone1";
      3;
      0,
      1,
      2;
      1.000000,
      1.000000,
      1.000000;
      1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
    }
  }
}
AnimationSet Wave {
  Animation {
    { Bone1 }
    AnimationKey {
      2;
      3;
      0;3;0.0,0.0,0.0;;,
      10;3;1.0,0.0,0.0;;,
      50;3;1.0,2.0,0.0;;;
    }
  }
}
)";
  const std::string file = testing::TempDir() + "conform_zero_tps.x";
  { std::ofstream(file) << x; }
  const auto m = io::import_model(file);
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].ticks_per_second, 25.0);
  EXPECT_DOUBLE_EQ(m.animations[0].duration(), 2.0);  // 50 ticks
  skin::Pose pose;
  m.animations[0].sample(m.skeleton, 0.4, skin::Blend::log, pose);  // tick 10: (1, 0, 0)
  skin::Skinner<double> s(m.skeleton, m.mesh.rest, m.influences);
  s.skin(pose, skin::SkinMode::cga);
  Eigen::Matrix3Xd out;
  s.write(out);
  EXPECT_LT((out.colwise() - Eigen::Vector3d(1, 0, 0) - m.mesh.current).cwiseAbs().maxCoeff(),
            1e-12);
  m.animations[0].sample(m.skeleton, 1.2, skin::Blend::linear, pose);  // tick 30: (1, 1, 0)
  s.skin(pose, skin::SkinMode::cga);
  s.write(out);
  EXPECT_LT((out.colwise() - Eigen::Vector3d(1, 1, 0) - m.mesh.current).cwiseAbs().maxCoeff(),
            1e-12);
}

}  // namespace
