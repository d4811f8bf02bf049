#include "conform/io/import.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/SVD>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <unordered_map>

#include "conform/io/crash_guard.hpp"
#include "conform/io/weld_model.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"

namespace conform::io {
namespace {

using skin::Versor;

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  for (unsigned r = 0; r < 4; ++r)
    for (unsigned c = 0; c < 4; ++c) e(r, c) = static_cast<double>(m[r][c]);
  return e;
}

// A 4×4 affine matrix [A t; 0 1] as a versor: A = U Σ Vᵀ, rotation U Vᵀ (the polar factor, the
// rotation nearest to A / scale), scale = mean singular value. Exact for a similarity; for a
// non-uniform scale it is "the mean scale" of the issue and `nonuniform` is set.
struct Decomposed {
  Versor versor;
  bool nonuniform = false;
  bool reflection = false;
};

std::optional<Decomposed> decompose(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) return std::nullopt;
  if (std::abs(m(3, 0)) > 1e-6 || std::abs(m(3, 1)) > 1e-6 || std::abs(m(3, 2)) > 1e-6 ||
      std::abs(m(3, 3) - 1) > 1e-6)
    return std::nullopt;
  const Eigen::Matrix3d a = m.topLeftCorner<3, 3>();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  if (!(sigma.minCoeff() > 1e-12 * std::max(1.0, sigma.maxCoeff()))) return std::nullopt;
  Eigen::Matrix3d u = svd.matrixU();
  Decomposed d;
  if ((u * svd.matrixV().transpose()).determinant() < 0) {
    u.col(2) = -u.col(2);  // a mirror is not a versor: keep the proper rotation
    d.reflection = true;
  }
  const Eigen::Matrix3d r = u * svd.matrixV().transpose();
  const double s = sigma.mean();
  d.nonuniform = (sigma.maxCoeff() - sigma.minCoeff()) > 1e-4 * s;
  d.versor = Versor::from_trs(m.topRightCorner<3, 1>(), Eigen::Quaterniond(r).normalized(), s);
  return d;
}

std::string node_name(const aiNode* n) {
  return n->mName.length ? n->mName.C_Str() : "(unnamed)";
}

struct Builder {
  std::string file;
  const aiScene* scene;
  ImportOptions options;
  SkinnedModel model;
  std::unordered_map<std::string, std::int32_t> joint_by_name;
  std::vector<std::int32_t> mesh_node;  // first node (DFS) referencing each mesh, −1 if none
  std::vector<Eigen::Matrix4d> offset_matrices;  // per bone, for de-duplication

  [[noreturn]] void fail(const std::string& problem) const { throw ImportError(file, problem); }
  void warn(const std::string& w) { model.warnings.push_back(w); }

  Versor to_versor(const aiMatrix4x4& m, const std::string& what) {
    const auto d = decompose(to_eigen(m));
    if (!d) fail(what + " has a NaN, singular or projective transform");
    if (d->nonuniform) warn(what + ": non-uniform scale replaced by its mean (not a versor)");
    if (d->reflection)
      warn(what + ": mirroring transform; the reflection is dropped (not a versor)");
    return d->versor;
  }

  void walk(const aiNode* node, std::int32_t parent) {
    const auto index = static_cast<std::int32_t>(model.skeleton.joints.size());
    skin::Joint j;
    j.name = node_name(node);
    j.parent = parent;
    j.rest = to_versor(node->mTransformation, "node '" + j.name + "'");
    model.skeleton.joints.push_back(std::move(j));
    joint_by_name.emplace(node->mName.C_Str(), index);  // the first node of a name wins
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned m = node->mMeshes[i];
      if (m < mesh_node.size() && mesh_node[m] < 0) mesh_node[m] = index;
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) walk(node->mChildren[c], index);
  }

  std::int32_t bone_for(const aiBone* b, const std::string& mesh_name) {
    const std::string name = b->mName.C_Str();
    auto it = joint_by_name.find(name);
    if (it == joint_by_name.end()) {
      // No node of that name (e.g. X/anim_test.x's joint3, joint4): the bone gets a root joint
      // of its own placed at its bind pose, G = B⁻¹, so that it holds its vertices where they
      // are unless an animation channel of that name moves it.
      const Versor offset = to_versor(b->mOffsetMatrix, "offset of bone '" + name + "'");
      const auto inv = offset.inverse();
      if (!inv) fail("offset of bone '" + name + "' is singular");
      skin::Joint j;
      j.name = name;
      j.rest = *inv;
      model.skeleton.joints.push_back(j);
      it = joint_by_name.emplace(name, model.skeleton.joint_count() - 1).first;
      warn("bone '" + name + "' of mesh '" + mesh_name +
           "' has no node of that name; it stays at its bind pose");
    }
    const Eigen::Matrix4d off = to_eigen(b->mOffsetMatrix);
    for (std::size_t i = 0; i < model.skeleton.bones.size(); ++i)
      if (model.skeleton.bones[i].joint == it->second && offset_matrices[i] == off)
        return static_cast<std::int32_t>(i);
    skin::Bone bone;
    bone.name = name;
    bone.joint = it->second;
    bone.offset = to_versor(b->mOffsetMatrix, "offset of bone '" + name + "'");
    model.skeleton.bones.push_back(bone);
    offset_matrices.push_back(off);
    return static_cast<std::int32_t>(model.skeleton.bones.size() - 1);
  }

  std::int32_t rigid_bone(std::int32_t joint) {
    const Eigen::Matrix4d id = Eigen::Matrix4d::Identity();
    for (std::size_t i = 0; i < model.skeleton.bones.size(); ++i)
      if (model.skeleton.bones[i].joint == joint && offset_matrices[i] == id)
        return static_cast<std::int32_t>(i);
    skin::Bone bone;
    bone.name = model.skeleton.joints[static_cast<std::size_t>(joint)].name;
    bone.joint = joint;
    model.skeleton.bones.push_back(bone);
    offset_matrices.push_back(id);
    return static_cast<std::int32_t>(model.skeleton.bones.size() - 1);
  }

  // Every mesh of the scene into one SkinnedMesh: vertices, triangles and bone weights, each
  // checked (indices in range, finite values, weights summing to 1).
  void meshes() {
    auto& mesh = model.mesh;
    std::size_t nv = 0, nf = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      nv += scene->mMeshes[m]->mNumVertices;
      nf += scene->mMeshes[m]->mNumFaces;
    }
    if (nv >= static_cast<std::size_t>(INT32_MAX)) fail("too many vertices");
    mesh.rest.resize(3, static_cast<Eigen::Index>(nv));
    mesh.faces.reserve(nf);
    bool all_normals = true, all_uvs = true;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      all_normals = all_normals && scene->mMeshes[m]->HasNormals();
      all_uvs = all_uvs && scene->mMeshes[m]->HasTextureCoords(0);
    }
    if (all_normals) mesh.normals.resize(3, static_cast<Eigen::Index>(nv));
    if (all_uvs) mesh.uvs.resize(2, static_cast<Eigen::Index>(nv));

    Influences inf(nv);
    std::int32_t base = 0;
    std::size_t skipped = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* am = scene->mMeshes[m];
      MeshInfo info;
      info.name = am->mName.length ? am->mName.C_Str() : "mesh " + std::to_string(m);
      info.first_vertex = base;
      info.vertex_count = static_cast<std::int32_t>(am->mNumVertices);
      info.first_face = static_cast<std::int32_t>(mesh.faces.size());
      info.bones = static_cast<std::int32_t>(am->mNumBones);
      info.joint = mesh_node[m];
      if (info.joint < 0) {
        warn("mesh '" + info.name + "' is not referenced by any node; placed at the root");
        info.joint = 0;
      }
      vertices(am, info, base, all_normals, all_uvs);
      skipped += triangles(am, info, base);
      info.face_count = static_cast<std::int32_t>(mesh.faces.size()) - info.first_face;
      weights(am, info, base, inf);
      model.meshes.push_back(info);
      base += info.vertex_count;
    }
    if (skipped) warn(std::to_string(skipped) + " point or line primitives ignored");
    if (mesh.faces.empty()) fail("contains no triangles");
    store_influences(inf, nv);
  }

  // Every vertex's bone influences, before the shared mesh keeps the 4 largest.
  using Influences = std::vector<std::vector<std::pair<std::int32_t, double>>>;

  void vertices(const aiMesh* am, const MeshInfo& info, std::int32_t base, bool all_normals,
                bool all_uvs) {
    auto& mesh = model.mesh;
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      const Eigen::Vector3d x(p.x, p.y, p.z);
      if (!x.allFinite())
        fail("mesh '" + info.name + "' vertex " + std::to_string(v) + " is NaN or infinite");
      mesh.rest.col(base + static_cast<std::int32_t>(v)) = x;
      if (all_normals) {
        const aiVector3D& n = am->mNormals[v];
        mesh.normals.col(base + static_cast<std::int32_t>(v)) = Eigen::Vector3d(n.x, n.y, n.z);
      }
      if (all_uvs) {
        const aiVector3D& t = am->mTextureCoords[0][v];
        mesh.uvs.col(base + static_cast<std::int32_t>(v)) = Eigen::Vector2d(t.x, t.y);
      }
    }
  }

  // The mesh's triangles, indices checked; returns how many other primitives were skipped.
  std::size_t triangles(const aiMesh* am, const MeshInfo& info, std::int32_t base) {
    auto& mesh = model.mesh;
    std::size_t skipped = 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) {
        ++skipped;
        continue;
      }
      mesh::Face tri;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices)
          fail("mesh '" + info.name + "' face " + std::to_string(f) + " refers to vertex " +
               std::to_string(face.mIndices[k]) + " of " + std::to_string(am->mNumVertices));
        tri[static_cast<std::size_t>(k)] = base + static_cast<std::int32_t>(face.mIndices[k]);
      }
      mesh.faces.push_back(tri);
    }
    return skipped;
  }

  // The mesh's bone weights (one rigid bone for a mesh without bones), checked and
  // renormalized.
  void weights(const aiMesh* am, const MeshInfo& info, std::int32_t base, Influences& inf) {
    if (am->mNumBones == 0) {
      const auto b = rigid_bone(info.joint);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        inf[static_cast<std::size_t>(base) + v].push_back({b, 1.0});
    } else {
      for (unsigned i = 0; i < am->mNumBones; ++i) {
        const aiBone* ab = am->mBones[i];
        const auto b = bone_for(ab, info.name);
        for (unsigned k = 0; k < ab->mNumWeights; ++k) {
          const aiVertexWeight& w = ab->mWeights[k];
          if (w.mVertexId >= am->mNumVertices)
            fail("bone '" + std::string(ab->mName.C_Str()) + "' of mesh '" + info.name +
                 "' refers to vertex " + std::to_string(w.mVertexId) + " of " +
                 std::to_string(am->mNumVertices));
          if (!std::isfinite(w.mWeight) || w.mWeight < 0)
            fail("bone '" + std::string(ab->mName.C_Str()) + "' of mesh '" + info.name +
                 "' has a NaN, infinite or negative weight");
          if (w.mWeight > 0)
            inf[static_cast<std::size_t>(base) + w.mVertexId].push_back({b, w.mWeight});
        }
      }
      // Weights must sum to 1. Exporters truncating to 4 influences without renormalizing
      // leave sums a little below 1 (FBX/huesitos.fbx: 0.948–1); those are renormalized with
      // a warning, anything further off is an error.
      std::size_t off = 0;
      double worst = 1;
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        auto& list = inf[static_cast<std::size_t>(base) + v];
        double sum = 0;
        for (const auto& bw : list) sum += bw.second;
        if (std::abs(sum - 1) > options.weight_tolerance)
          fail("the bone weights of vertex " + std::to_string(v) + " of mesh '" + info.name +
               "' sum to " + std::to_string(sum) + ", not 1");
        if (std::abs(sum - 1) > 1e-4) {
          ++off;
          if (std::abs(sum - 1) > std::abs(worst - 1)) worst = sum;
        }
        for (auto& bw : list) bw.second /= sum;
      }
      if (off)
        warn("mesh '" + info.name + "': the weights of " + std::to_string(off) +
             " vertices do not sum to 1 (worst " + std::to_string(worst) + "); renormalized");
    }
  }

  // The influence lists, and the shared mesh's 4 largest (renormalized, sorted decreasing).
  void store_influences(const Influences& inf, std::size_t nv) {
    auto& mesh = model.mesh;
    auto& lists = model.influences;
    lists.offsets.assign(1, 0);
    for (const auto& v : inf) {
      for (const auto& [b, w] : v) {
        lists.bones.push_back(b);
        lists.weights.push_back(w);
      }
      lists.offsets.push_back(static_cast<std::int32_t>(lists.bones.size()));
    }
    // The shared mesh keeps the 4 largest, renormalized, sorted decreasing.
    const auto four = skin::Influences<double>::select(lists, mesh::kMaxInfluences);
    mesh.bones.resize(mesh::kMaxInfluences, static_cast<Eigen::Index>(nv));
    mesh.weights.resize(mesh::kMaxInfluences, static_cast<Eigen::Index>(nv));
    for (std::size_t v = 0; v < nv; ++v)
      for (std::size_t k = 0; k < static_cast<std::size_t>(mesh::kMaxInfluences); ++k) {
        mesh.bones(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(v)) =
            four.bones[k * nv + v];
        mesh.weights(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(v)) =
            four.weights[k * nv + v];
      }
  }

  void animations() {
    for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
      const aiAnimation* aa = scene->mAnimations[a];
      skin::Animation anim;
      anim.name = aa->mName.length ? aa->mName.C_Str() : "animation " + std::to_string(a);
      anim.duration_ticks = aa->mDuration;
      anim.ticks_per_second = aa->mTicksPerSecond != 0 ? aa->mTicksPerSecond : 25.0;
      for (unsigned c = 0; c < aa->mNumChannels; ++c) {
        const aiNodeAnim* na = aa->mChannels[c];
        const std::string node = na->mNodeName.C_Str();
        const auto it = joint_by_name.find(node);
        if (it == joint_by_name.end()) {
          warn("animation '" + anim.name + "': channel for unknown node '" + node + "' ignored");
          continue;
        }
        skin::Channel ch;
        ch.joint = it->second;
        for (unsigned k = 0; k < na->mNumPositionKeys; ++k) {
          const auto& key = na->mPositionKeys[k];
          ch.translation.push_back(
              {key.mTime, Eigen::Vector3d(key.mValue.x, key.mValue.y, key.mValue.z)});
        }
        for (unsigned k = 0; k < na->mNumRotationKeys; ++k) {
          const auto& key = na->mRotationKeys[k];
          ch.rotation.push_back({key.mTime, Eigen::Quaterniond(key.mValue.w, key.mValue.x,
                                                               key.mValue.y, key.mValue.z)});
        }
        bool warned = false;
        for (unsigned k = 0; k < na->mNumScalingKeys; ++k) {
          const auto& key = na->mScalingKeys[k];
          const Eigen::Vector3d s(key.mValue.x, key.mValue.y, key.mValue.z);
          const double mean = s.mean();
          if (!warned && s.allFinite() && (s.maxCoeff() - s.minCoeff()) > 1e-4 * std::abs(mean)) {
            warn("animation '" + anim.name + "', node '" + node +
                 "': non-uniform scale keys replaced by their mean (not a versor)");
            warned = true;
          }
          ch.scale.push_back({key.mTime, mean});
        }
        anim.channels.push_back(std::move(ch));
      }
      if (const auto e = anim.validate(model.skeleton); !e.empty()) fail(e);
      model.animations.push_back(std::move(anim));
    }
  }
};

// The bind pose in world space: every node at its own transform, skinned with eq 17.
void pose_current(SkinnedModel& m) {
  skin::Skinner<double> s(m.skeleton, m.mesh.rest, m.influences);
  s.skin(skin::Pose::rest(m.skeleton), skin::SkinMode::cga);
  s.write(m.mesh.current);
}

// Reads the file in a forked child first; empty when the child did not crash (it may still have
// failed: the real read reports that), else why it crashed.
std::string crashes_assimp(const std::string& file) {
  const std::string signal = crash_in_child([&] {
    Assimp::Importer importer;
    importer.ReadFile(file, import_flags());
  });
  if (signal.empty()) return {};
  return "assimp crashed reading it (" + signal +
         "); the file is corrupt (e.g. bone or vertex indices out of range)";
}

}  // namespace

int SkinnedModel::find_animation(const std::string& key) const {
  for (std::size_t i = 0; i < animations.size(); ++i)
    if (animations[i].name == key) return static_cast<int>(i);
  int index = -1;
  const auto r = std::from_chars(key.data(), key.data() + key.size(), index);
  if (r.ec == std::errc() && r.ptr == key.data() + key.size() && index >= 0 &&
      index < static_cast<int>(animations.size()))
    return index;
  return -1;
}

unsigned import_flags() {
  return aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure;
}

SkinnedModel import_model(const std::filesystem::path& path, const ImportOptions& options) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw ImportError(file, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw ImportError(file, "is a directory");
  if (!std::ifstream(path, std::ios::binary))
    throw ImportError(file, "cannot be opened for reading");
  Assimp::Importer importer;
  const std::string ext = path.extension().string();
  if (ext.empty() || !importer.IsExtensionSupported(ext))
    throw ImportError(file, "unsupported format '" + ext + "' (assimp has no importer for it)");
  if (options.crash_guard)
    if (const auto why = crashes_assimp(file); !why.empty()) throw ImportError(file, why);
  const aiScene* scene = importer.ReadFile(file, import_flags());
  if (!scene) {
    std::string why = importer.GetErrorString();
    if (why.empty()) why = "unknown reason";
    throw ImportError(file, "cannot be read (truncated, corrupt or not this format?): " + why);
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
    throw ImportError(file, "incomplete scene (no mesh data)");
  if (scene->mNumMeshes == 0) throw ImportError(file, "contains no meshes");

  Builder b{file, scene, options, {}, {}, std::vector<std::int32_t>(scene->mNumMeshes, -1), {}};
  b.model.source = file;
  b.walk(scene->mRootNode, -1);
  b.meshes();
  b.animations();
  if (const auto e = b.model.skeleton.validate(); !e.empty()) b.fail(e);
  if (const auto e =
          b.model.influences.validate(b.model.skeleton.bone_count(), options.weight_tolerance);
      !e.empty())
    b.fail(e);
  if (options.weld) weld_model(b.model, options.weld_options);
  pose_current(b.model);
  return std::move(b.model);
}

SkinnedModel arm_model(int resolution) {
  mesh::Arm arm = mesh::make_arm(resolution);
  SkinnedModel m;
  m.source = "arm:" + std::to_string(resolution);
  m.influences = skin::InfluenceLists::from_mesh(arm.mesh);
  m.mesh = std::move(arm.mesh);
  m.skeleton = std::move(arm.skeleton);
  MeshInfo info;
  info.name = "arm";
  info.vertex_count = m.mesh.vertex_count();
  info.face_count = m.mesh.face_count();
  info.bones = m.skeleton.bone_count();
  m.meshes.push_back(info);
  return m;
}

SkinnedModel load_model(const std::string& spec, const ImportOptions& options) {
  if (spec == "arm") return arm_model(1);
  if (spec.rfind("arm:", 0) == 0) {
    int n = 0;
    const char* b = spec.data() + 4;
    const char* e = spec.data() + spec.size();
    const auto r = std::from_chars(b, e, n);
    if (r.ec != std::errc() || r.ptr != e || n < 1 || n > 200)
      throw ImportError(spec, "the arm's resolution must be an integer in [1, 200]");
    return arm_model(n);
  }
  return import_model(spec, options);
}

}  // namespace conform::io
