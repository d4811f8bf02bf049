#include "conform/io/import.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/LU>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

#include "conform/io/isolate.hpp"
#include "conform/io/model_check.hpp"
#include "conform/io/model_wire.hpp"
#include "conform/io/weld_model.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "import_budget.hpp"
#include "similarity.hpp"
#include "skinning_error.hpp"

namespace conform::io {
namespace {

using skin::Versor;

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  for (unsigned r = 0; r < 4; ++r)
    for (unsigned c = 0; c < 4; ++c) e(r, c) = static_cast<double>(m[r][c]);
  return e;
}

std::string node_name(const aiNode* n) {
  return n->mName.length ? n->mName.C_Str() : "(unnamed)";
}

// What the importer knows of a joint besides its versor: the file's global matrix at rest
// (identity for a bone without a node), whether that global mirrors (its parity, conjugated
// out of the versors with F), the versor of its global at rest, and whether every versor
// from the root down to it is exact.
struct JointFrame {
  const aiNode* node = nullptr;  // null for a bone without a node
  Eigen::Matrix4d global = Eigen::Matrix4d::Identity();
  bool odd = false;
  Versor global_versor;
  bool exact_chain = true;
  bool exact = true;  // its own versor
  bool used = false;  // a bone's joint or one of their ancestors: it moves vertices
};

// Vertices whose weights do not sum to 1, over the whole model (one summary warning).
struct WeightSums {
  std::size_t off = 0;
  double lowest = 1, highest = 1;
};

constexpr double kWeightSumNoise = 1e-4;  // |Σ w − 1| renormalized silently (float noise)

struct Builder {
  std::string file;
  const aiScene* scene;
  ImportOptions options;
  SkinnedModel model{};
  std::unordered_map<std::string, std::int32_t> joint_by_name{};
  std::unordered_map<const aiNode*, std::int32_t> joint_of_node{};
  std::vector<JointFrame> frames{};               // per joint
  std::vector<detail::MeshInstance> instances{};  // every (mesh, node) placement
  std::vector<Eigen::Matrix4d> bone_keys{};       // per bone, O K⁻¹, for de-duplication
  std::vector<std::string> approximated{};        // transforms that are not proper similarities
  WeightSums sums{};
  std::size_t repeated_vertex_faces = 0;

  [[noreturn]] void fail(const std::string& problem) const { throw ImportError(file, problem); }
  void warn(const std::string& w) { model.warnings.push_back(w); }

  // The nearest versor; an approximation is recorded, or returned in `exact` when given.
  Versor to_versor(const Eigen::Matrix4d& m, const std::string& what, bool* exact = nullptr) {
    const auto d = detail::nearest_versor(m);
    if (!d) fail(what + " has a NaN, singular or projective transform");
    if (exact)
      *exact = d->exact;
    else if (!d->exact)
      approximated.push_back(what);
    return d->versor;
  }

  // Marks `joint` and its ancestors as moving vertices; their approximated versors count.
  void use(std::int32_t joint) {
    for (auto j = joint; j >= 0; j = model.skeleton.joints[static_cast<std::size_t>(j)].parent) {
      JointFrame& f = frames[static_cast<std::size_t>(j)];
      if (f.used) return;
      f.used = true;
      if (!f.exact)
        approximated.push_back("node '" + model.skeleton.joints[static_cast<std::size_t>(j)].name +
                               "'");
    }
  }

  // Every node becomes a joint. A mirroring node makes its subtree odd: its versor is the
  // proper F^parent L F^self, so that the versors' product along a chain is G F^odd. The
  // parent is the node's mParent when that was visited already: assimp's HL1 MDL loader
  // lists a bone chain as siblings whose mParent pointers hold the real chain (and the
  // offsets match that), e.g. MDL/MDL (HL1)/man.mdl.
  void add_joint(const aiNode* node, std::int32_t parent) {
    const auto index = static_cast<std::int32_t>(model.skeleton.joints.size());
    if (node->mParent && parent >= 0 &&
        frames[static_cast<std::size_t>(parent)].node != node->mParent)
      if (const auto it = joint_of_node.find(node->mParent); it != joint_of_node.end())
        parent = it->second;
    const Eigen::Matrix4d local = to_eigen(node->mTransformation);
    JointFrame f;
    f.node = node;
    const bool parent_odd = parent >= 0 && frames[static_cast<std::size_t>(parent)].odd;
    f.odd = parent_odd != (local.topLeftCorner<3, 3>().determinant() < 0);
    f.global = parent >= 0
                   ? Eigen::Matrix4d(frames[static_cast<std::size_t>(parent)].global * local)
                   : local;
    skin::Joint j;
    j.name = node_name(node);
    j.parent = parent;
    j.rest =
        to_versor(detail::reflected(local, parent_odd, f.odd), "node '" + j.name + "'", &f.exact);
    f.exact_chain = f.exact;
    if (parent >= 0) {
      const JointFrame& p = frames[static_cast<std::size_t>(parent)];
      f.global_versor = p.global_versor * j.rest;
      f.exact_chain = f.exact && p.exact_chain;
    } else {
      f.global_versor = j.rest;
    }
    model.skeleton.joints.push_back(std::move(j));
    frames.push_back(f);
    joint_by_name.emplace(node->mName.C_Str(), index);  // the first node of a name wins
    joint_of_node.emplace(node, index);
    for (unsigned i = 0; i < node->mNumMeshes; ++i)
      if (node->mMeshes[i] < scene->mNumMeshes) instances.push_back({node->mMeshes[i], node});
  }

  // Depth-first, parents first, children in file order, with an explicit stack: a file sets
  // the depth (a 20,000-node chain must not overflow the call stack). A node reached twice (a
  // cycle, or a node shared by two parents) is refused.
  void walk(const aiNode* root) {
    std::vector<std::pair<const aiNode*, std::int32_t>> stack{{root, -1}};
    while (!stack.empty()) {
      const auto [node, parent] = stack.back();
      stack.pop_back();
      if (!node) fail("the node hierarchy has a null child");
      if (joint_of_node.count(node))
        fail("node '" + node_name(node) + "' appears twice in the node hierarchy (a cycle?)");
      const auto index = static_cast<std::int32_t>(model.skeleton.joints.size());
      add_joint(node, parent);
      for (unsigned c = node->mNumChildren; c-- > 0;) stack.emplace_back(node->mChildren[c], index);
    }
  }

  // Instances in mesh order (a mesh's instances in node order); a mesh no node places gets one
  // instance at the root.
  void order_instances() {
    std::vector<detail::MeshInstance> ordered;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const auto before = ordered.size();
      for (const auto& in : instances)
        if (in.mesh == m) ordered.push_back(in);
      if (ordered.size() == before) {
        const aiMesh* am = scene->mMeshes[m];
        warn("mesh '" + (am->mName.length ? std::string(am->mName.C_Str()) : std::to_string(m)) +
             "' is not referenced by any node; placed at the root");
        ordered.push_back({m, scene->mRootNode});
      }
    }
    instances = std::move(ordered);
  }

  std::int32_t joint_of(const aiNode* node) const {
    const auto it = joint_of_node.find(node);
    return it == joint_of_node.end() ? 0 : it->second;
  }

  // A bone without a node of its name (e.g. X/anim_test.x's joint3, joint4) gets a root
  // joint of its own at its bind pose (O⁻¹), so that it holds its vertices where they are
  // unless an animation channel of that name moves it.
  std::int32_t nodeless_joint(const aiBone* b, const std::string& mesh_name) {
    const std::string name = b->mName.C_Str();
    const std::string what = "offset of bone '" + name + "'";
    const auto inv = to_versor(to_eigen(b->mOffsetMatrix), what).inverse();
    if (!inv) fail(what + " is singular");
    skin::Joint j;
    j.name = name;
    j.rest = *inv;
    model.skeleton.joints.push_back(j);
    JointFrame f;
    f.global_versor = *inv;
    frames.push_back(f);
    warn("bone '" + name + "' of mesh '" + mesh_name +
         "' has no node of that name; it stays at its bind pose");
    return joint_by_name.emplace(name, model.skeleton.joint_count() - 1).first->second;
  }

  // The skinning matrix of a bone on `joint` with file offset `offset` at the rest pose, in
  // baked space: G O N⁻¹ (a bone without a node: N⁻¹, matrix skinning leaves it in place).
  Eigen::Matrix4d rest_skinning(std::int32_t joint, const Eigen::Matrix4d& offset,
                                const Eigen::Matrix4d& bake_inverse) const {
    const JointFrame& f = frames[static_cast<std::size_t>(joint)];
    return f.node ? Eigen::Matrix4d(f.global * offset * bake_inverse) : bake_inverse;
  }

  // The bone (joint, O N⁻¹), shared by meshes that bind it alike. Below a chain of exact
  // versors its versor is that of F^odd O N⁻¹ (G̃ F^odd = G exactly). Below a chain with an
  // approximated node it is B = G̃⁻¹ · versor(G O N⁻¹), G̃ the joint's global versor at rest:
  // the rest pose is then still exact (whenever G O N⁻¹ is a proper similarity).
  std::int32_t bone(std::int32_t joint, const std::string& name, const Eigen::Matrix4d& offset,
                    const Eigen::Matrix4d& bake_inverse) {
    const Eigen::Matrix4d key = offset * bake_inverse;
    for (std::size_t i = 0; i < model.skeleton.bones.size(); ++i)
      if (model.skeleton.bones[i].joint == joint && bone_keys[i] == key)
        return static_cast<std::int32_t>(i);
    use(joint);
    const JointFrame& f = frames[static_cast<std::size_t>(joint)];
    const std::string what = "bind transform of bone '" + name + "'";
    skin::Bone b;
    b.name = name;
    b.joint = joint;
    if (f.exact_chain) {
      b.offset = to_versor(detail::reflected(key, f.odd, false), what);
    } else {
      const auto inv = f.global_versor.inverse();
      if (!inv) fail("node '" + name + "' has a singular transform");
      b.offset = *inv * to_versor(rest_skinning(joint, offset, bake_inverse), what);
    }
    model.skeleton.bones.push_back(b);
    bone_keys.push_back(key);
    return static_cast<std::int32_t>(model.skeleton.bones.size() - 1);
  }

  // The bind transform K of an instance: the mesh node's global transform when it makes
  // every bone's rest skinning matrix G O K⁻¹ a proper similarity (the usual case); else the
  // bind transform its first bone's offset implies (G O: a file whose offsets ignore a
  // mirroring mesh node, as X/test_cube_*.x); else the node's, with the bones' transforms
  // approximated.
  Eigen::Matrix4d bind_transform(const detail::MeshInstance& in) {
    const aiMesh* am = scene->mMeshes[in.mesh];
    const Eigen::Matrix4d node = frames[static_cast<std::size_t>(joint_of(in.node))].global;
    if (am->mNumBones == 0) return node;
    std::vector<std::pair<std::int32_t, Eigen::Matrix4d>> bones;
    for (unsigned i = 0; i < am->mNumBones; ++i) {
      const auto it = joint_by_name.find(am->mBones[i]->mName.C_Str());
      if (it != joint_by_name.end() && frames[static_cast<std::size_t>(it->second)].node)
        bones.push_back({it->second, to_eigen(am->mBones[i]->mOffsetMatrix)});
    }
    const auto all_similar = [&](const Eigen::Matrix4d& k) {
      const Eigen::Matrix4d inv = k.inverse();
      if (!inv.allFinite()) return false;
      for (const auto& [joint, offset] : bones)
        if (!detail::is_proper_similarity(rest_skinning(joint, offset, inv))) return false;
      return true;
    };
    if (bones.empty() || all_similar(node)) return node;
    const Eigen::Matrix4d implied =
        frames[static_cast<std::size_t>(bones.front().first)].global * bones.front().second;
    return all_similar(implied) ? implied : node;
  }

  // What of K is baked into the rest positions: N = Q⁻¹ K, Q the nearest proper similarity
  // to K, which the versors carry. N is the identity (and nothing is baked) when K is a proper
  // similarity, its non-uniform stretch or mirror otherwise.
  static Eigen::Matrix4d baked_part(const Eigen::Matrix4d& k) {
    const auto q = detail::nearest_versor(k);
    if (!q || q->exact) return Eigen::Matrix4d::Identity();
    return q->versor.matrix().inverse() * k;
  }

  // Every instance of every mesh into one SkinnedMesh: vertices (baked), triangles and bone
  // weights, each checked (indices in range, finite values, weights summing to 1).
  void meshes() {
    order_instances();
    auto& mesh = model.mesh;
    std::size_t nv = 0, nf = 0;
    bool all_normals = true, all_uvs = true;
    for (const auto& in : instances) {
      const aiMesh* am = scene->mMeshes[in.mesh];
      nv += am->mNumVertices, nf += am->mNumFaces;
      all_normals = all_normals && am->HasNormals();
      all_uvs = all_uvs && am->HasTextureCoords(0);
    }
    if (nv >= static_cast<std::size_t>(INT32_MAX)) fail("too many vertices");
    mesh.rest.resize(3, static_cast<Eigen::Index>(nv));
    mesh.faces.reserve(nf);
    if (all_normals) mesh.normals.resize(3, static_cast<Eigen::Index>(nv));
    if (all_uvs) mesh.uvs.resize(2, static_cast<Eigen::Index>(nv));

    Influences inf(nv);
    std::int32_t base = 0;
    std::size_t skipped = 0;
    for (auto& in : instances) {
      const aiMesh* am = scene->mMeshes[in.mesh];
      MeshInfo info;
      info.name = am->mName.length ? am->mName.C_Str() : "mesh " + std::to_string(in.mesh);
      info.source = static_cast<std::int32_t>(in.mesh);
      info.first_vertex = base;
      info.vertex_count = static_cast<std::int32_t>(am->mNumVertices);
      info.first_face = static_cast<std::int32_t>(mesh.faces.size());
      info.bones = static_cast<std::int32_t>(am->mNumBones);
      info.joint = joint_of(in.node);
      in.first_vertex = base;
      in.bake = baked_part(bind_transform(in));
      vertices(am, info, base, in.bake, all_normals, all_uvs);
      skipped += triangles(am, info, base, in.bake.topLeftCorner<3, 3>().determinant() < 0);
      info.face_count = static_cast<std::int32_t>(mesh.faces.size()) - info.first_face;
      weights(am, info, base, in.bake.inverse(), inf);
      model.meshes.push_back(info);
      base += info.vertex_count;
    }
    if (skipped) warn(std::to_string(skipped) + " point or line primitives ignored");
    if (repeated_vertex_faces)
      warn(std::to_string(repeated_vertex_faces) +
           " triangles that repeat a vertex (zero area) dropped");
    if (mesh.faces.empty()) fail("contains no triangles");
    if (sums.off)
      warn("the bone weights of " + std::to_string(sums.off) + " vertices do not sum to 1 (" +
           std::to_string(sums.lowest) + " to " + std::to_string(sums.highest) +
           "); renormalized (strict weights would refuse the model)");
    store_influences(inf, nv);
  }

  // Every vertex's bone influences, before the shared mesh keeps the 4 largest.
  using Influences = std::vector<std::vector<std::pair<std::int32_t, double>>>;

  // Positions baked by K, normals by K's inverse transpose (renormalized).
  void vertices(const aiMesh* am, const MeshInfo& info, std::int32_t base,
                const Eigen::Matrix4d& bake, bool all_normals, bool all_uvs) {
    auto& mesh = model.mesh;
    const Eigen::Matrix3d a = bake.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = bake.topRightCorner<3, 1>();
    const Eigen::Matrix3d normal_map = a.inverse().transpose();
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      const Eigen::Vector3d x(p.x, p.y, p.z);
      if (!x.allFinite())
        fail("mesh '" + info.name + "' vertex " + std::to_string(v) + " is NaN or infinite");
      const auto col = base + static_cast<std::int32_t>(v);
      mesh.rest.col(col) = a * x + t;
      if (all_normals) {
        const aiVector3D& n = am->mNormals[v];
        const Eigen::Vector3d baked = normal_map * Eigen::Vector3d(n.x, n.y, n.z);
        const double length = baked.norm();
        // A degenerate corner's normal (assimp's NaN) becomes 0: "no normal", not NaN.
        mesh.normals.col(col) = length > 0 && std::isfinite(length)
                                    ? Eigen::Vector3d(baked / length)
                                    : Eigen::Vector3d::Zero();
      }
      if (all_uvs) {
        const aiVector3D& uv = am->mTextureCoords[0][v];
        const Eigen::Vector2d st(uv.x, uv.y);
        if (!st.allFinite())
          fail("mesh '" + info.name + "' vertex " + std::to_string(v) +
               " has a NaN or infinite UV");
        mesh.uvs.col(col) = st;
      }
    }
  }

  // The mesh's triangles, indices checked (wound the other way when K mirrors, so that faces
  // keep facing their normals); returns how many other primitives were skipped.
  std::size_t triangles(const aiMesh* am, const MeshInfo& info, std::int32_t base, bool mirrored) {
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
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
        ++repeated_vertex_faces;  // assimp makes these from coincident corners (.dxf)
        continue;
      }
      if (mirrored) std::swap(tri[1], tri[2]);
      mesh.faces.push_back(tri);
    }
    return skipped;
  }

  // The mesh's bone weights (one rigid bone on its node for a mesh without bones), checked and
  // normalized.
  void weights(const aiMesh* am, const MeshInfo& info, std::int32_t base,
               const Eigen::Matrix4d& bake_inverse, Influences& inf) {
    if (am->mNumBones == 0) {
      const auto b =
          bone(info.joint, model.skeleton.joints[static_cast<std::size_t>(info.joint)].name,
               Eigen::Matrix4d::Identity(), bake_inverse);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        inf[static_cast<std::size_t>(base) + v].push_back({b, 1.0});
      return;
    }
    for (unsigned i = 0; i < am->mNumBones; ++i) {
      const aiBone* ab = am->mBones[i];
      const std::string name = ab->mName.C_Str();
      auto it = joint_by_name.find(name);
      const std::int32_t joint =
          it != joint_by_name.end() ? it->second : nodeless_joint(ab, info.name);
      const auto b = bone(joint, name, to_eigen(ab->mOffsetMatrix), bake_inverse);
      for (unsigned k = 0; k < ab->mNumWeights; ++k) {
        const aiVertexWeight& w = ab->mWeights[k];
        if (w.mVertexId >= am->mNumVertices)
          fail("bone '" + name + "' of mesh '" + info.name + "' refers to vertex " +
               std::to_string(w.mVertexId) + " of " + std::to_string(am->mNumVertices));
        if (!std::isfinite(w.mWeight) || w.mWeight < 0)
          fail("bone '" + name + "' of mesh '" + info.name +
               "' has a NaN, infinite or negative weight");
        if (w.mWeight > 0)
          inf[static_cast<std::size_t>(base) + w.mVertexId].push_back({b, w.mWeight});
      }
    }
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      normalize(inf[static_cast<std::size_t>(base) + v], v, info);
  }

  // Weights must sum to 1. Exporters truncating influences without renormalizing, or Blender
  // exports (FBX/animation_with_skeleton.fbx: 0.94–1.38), do not; engines normalize on import,
  // and so does this by default. With strict_weights a sum off by more than float noise is an
  // error. A vertex without any weight cannot be skinned at all.
  void normalize(std::vector<std::pair<std::int32_t, double>>& list, unsigned v,
                 const MeshInfo& info) {
    double sum = 0;
    for (const auto& bw : list) sum += bw.second;
    const std::string vertex = "vertex " + std::to_string(v) + " of mesh '" + info.name + "'";
    if (!(sum > 0)) fail("the bones of " + vertex + " give it no weight");
    if (std::abs(sum - 1) > kWeightSumNoise) {
      if (options.strict_weights)
        fail("the bone weights of " + vertex + " sum to " + std::to_string(sum) +
             ", not 1 (strict weights)");
      ++sums.off;
      sums.lowest = std::min(sums.lowest, sum), sums.highest = std::max(sums.highest, sum);
    }
    for (auto& bw : list) bw.second /= sum;
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

  // One node channel as keys of the joint's versor F^parent L(t) F^self: translations and
  // rotations reflected, scale vectors made positive by a constant rotation folded into the
  // rotation keys (a sign pattern with an even number of flips is a half turn).
  skin::Channel channel(const aiNodeAnim* na, std::int32_t joint, const std::string& what) {
    const JointFrame& f = frames[static_cast<std::size_t>(joint)];
    const std::int32_t parent = model.skeleton.joints[static_cast<std::size_t>(joint)].parent;
    const bool left = parent >= 0 && frames[static_cast<std::size_t>(parent)].odd;
    skin::Channel ch;
    ch.joint = joint;
    for (unsigned k = 0; k < na->mNumPositionKeys; ++k) {
      const auto& key = na->mPositionKeys[k];
      Eigen::Vector3d t(key.mValue.x, key.mValue.y, key.mValue.z);
      if (left) t.z() = -t.z();
      ch.translation.push_back({key.mTime, t});
    }
    // The sign pattern of F^parent S F^self, from the first scale key.
    Eigen::Vector3d signs(1, 1, left != f.odd ? -1 : 1);
    if (na->mNumScalingKeys) {
      const auto& s = na->mScalingKeys[0].mValue;
      signs =
          signs.cwiseProduct(Eigen::Vector3d(s.x < 0 ? -1 : 1, s.y < 0 ? -1 : 1, s.z < 0 ? -1 : 1));
    }
    bool inexact = signs.prod() < 0;  // the animation changes the node's parity
    Eigen::Matrix3d flips = Eigen::Matrix3d::Identity();
    if (signs.prod() > 0) flips = signs.asDiagonal();
    const Eigen::Quaterniond half_turn(flips);
    for (unsigned k = 0; k < na->mNumRotationKeys; ++k) {
      const auto& key = na->mRotationKeys[k];
      Eigen::Quaterniond q(key.mValue.w, key.mValue.x, key.mValue.y, key.mValue.z);
      if (left) q = detail::reflected(q);
      ch.rotation.push_back({key.mTime, q * half_turn});
    }
    for (unsigned k = 0; k < na->mNumScalingKeys; ++k) {
      const auto& key = na->mScalingKeys[k];
      Eigen::Vector3d s(key.mValue.x, key.mValue.y, key.mValue.z);
      if (left != f.odd) s.z() = -s.z();
      const Eigen::Vector3d positive = s.cwiseProduct(signs);
      if (!positive.allFinite() || positive.minCoeff() <= 0 ||
          positive.maxCoeff() - positive.minCoeff() > 1e-5 * positive.mean())
        inexact = true;
      ch.scale.push_back({key.mTime, s.allFinite() ? positive.cwiseAbs().mean() : s.mean()});
    }
    if (inexact && f.used) approximated.push_back(what);
    return ch;
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
        anim.channels.push_back(
            channel(na, it->second, "animation '" + anim.name + "', node '" + node + "'"));
      }
      if (const auto e = anim.validate(model.skeleton); !e.empty()) fail(e);
      model.animations.push_back(std::move(anim));
    }
  }

  // When some transform is not a proper similarity, CGA skinning may differ from matrix
  // skinning: measure by how much, and say so when it is more than rounding.
  void report_approximations() {
    if (approximated.empty()) return;
    const auto e = detail::skinning_error(*scene, model, instances);
    if (!(e.worst > kExactSkinning * e.diagonal)) return;
    std::string list;
    for (std::size_t i = 0; i < approximated.size() && i < 4; ++i)
      list += (i ? ", " : "") + approximated[i];
    if (approximated.size() > 4) list += ", ... (" + std::to_string(approximated.size()) + ")";
    std::ostringstream os;
    os << "non-uniform scales or mirrors that versors cannot represent (" << list
       << ") are approximated by the nearest similarity: skinning deviates from matrix skinning "
          "by up to "
       << e.worst / e.diagonal << " of the model's diagonal (" << e.worst << " units, at "
       << e.where << ")";
    warn(os.str());
  }
  static constexpr double kExactSkinning = 1e-6;  // float storage: files are exact to ~1e-7
};

// The bind pose in world space: every node at its own transform, skinned with eq 17.
void pose_current(SkinnedModel& m) {
  skin::Skinner<double> s(m.skeleton, m.mesh.rest, m.influences);
  s.skin(skin::Pose::rest(m.skeleton), skin::SkinMode::cga);
  s.write(m.mesh.current);
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

namespace {

// The file's unit in centimetres, when it states one (FBX: UnitScaleFactor, a float or a
// double by assimp version); 0 otherwise, or when the value is not a positive finite number.
double unit_scale_cm(const aiScene& scene) {
  if (!scene.mMetaData) return 0;
  double d = 0;
  float f = 0;
  if (!scene.mMetaData->Get("UnitScaleFactor", d) && scene.mMetaData->Get("UnitScaleFactor", f))
    d = f;
  return std::isfinite(d) && d > 0 ? d : 0;
}

// The import itself, in this process.
SkinnedModel import_here(const std::string& file, const ImportOptions& options) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file, import_flags());
  if (!scene) {
    std::string why = importer.GetErrorString();
    if (why.empty()) why = "unknown reason";
    throw ImportError(file, "cannot be read (truncated, corrupt or not this format?): " + why);
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
    throw ImportError(file, "incomplete scene (no mesh data)");
  if (scene->mNumMeshes == 0) throw ImportError(file, "contains no meshes");

  Builder b{file, scene, options};
  b.model.source = file;
  b.model.unit_scale_cm = unit_scale_cm(*scene);
  b.walk(scene->mRootNode);
  b.meshes();
  b.animations();
  if (const auto e = b.model.skeleton.validate(); !e.empty()) b.fail(e);
  if (const auto e = b.model.influences.validate(b.model.skeleton.bone_count(), kWeightSumNoise);
      !e.empty())
    b.fail(e);
  b.report_approximations();  // on the file's own vertices, before the weld renumbers them
  if (options.weld) weld_model(b.model, options.weld_options);
  pose_current(b.model);
  return std::move(b.model);
}

// The import in a child process (isolate.hpp); this process only decodes the child's model.
SkinnedModel import_isolated(const std::string& file, const ImportOptions& options) {
  IsolationLimits limits = options.isolation;
  limits.seconds = import_seconds(options.isolation, import_bytes(file));
  const Isolated r = run_isolated([&] { return encode_model(import_here(file, options)); }, limits);
  if (r.status != Isolated::Status::ok) throw isolation_error(file, r, limits);
  SkinnedModel model;
  try {
    model = decode_model(r.result);
  } catch (const std::exception& e) {
    throw ImportError(file,
                      std::string("the isolated import sent a bad result (") + e.what() + ")");
  }
  // A child whose memory assimp corrupted may still send a whole message of garbage.
  if (const std::string e = check_model(model); !e.empty())
    throw ImportError(file, "the isolated import sent an inconsistent model (" + e + ")");
  return model;
}

}  // namespace

SkinnedModel import_model(const std::filesystem::path& path, const ImportOptions& options) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw ImportError(file, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw ImportError(file, "is a directory");
  if (!std::filesystem::is_regular_file(path, ec))  // a FIFO would block the open below
    throw ImportError(file, "is not a regular file (a FIFO, socket or device?)");
  if (!std::ifstream(path, std::ios::binary))
    throw ImportError(file, "cannot be opened for reading");
  const std::string ext = path.extension().string();
  if (ext.empty() || !Assimp::Importer().IsExtensionSupported(ext))
    throw ImportError(file, "unsupported format '" + ext + "' (assimp has no importer for it)");
  return options.isolate ? import_isolated(file, options) : import_here(file, options);
}

SkinnedModel arm_model(int resolution) {
  skin::Arm arm = skin::make_arm(resolution);
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
    if (r.ec != std::errc() || r.ptr != e || n < 1 || n > skin::kMaxArmResolution)
      throw ImportError(spec, "the arm's resolution must be an integer in [1, " +
                                  std::to_string(skin::kMaxArmResolution) + "]");
    return arm_model(n);
  }
  return import_model(spec, options);
}

}  // namespace conform::io
