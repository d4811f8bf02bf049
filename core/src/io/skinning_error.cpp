#include "skinning_error.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "conform/skin/skinner.hpp"

namespace conform::io::detail {
namespace {

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  for (unsigned r = 0; r < 4; ++r)
    for (unsigned c = 0; c < 4; ++c) e(r, c) = static_cast<double>(m[r][c]);
  return e;
}

// The value of one key track at `ticks`, linearly interpolated (end keys hold outside).
template <class Key, class Lerp>
auto track(const Key* keys, unsigned n, double ticks, Lerp lerp) {
  if (ticks <= keys[0].mTime || n == 1) return lerp(keys[0].mValue, keys[0].mValue, 0.0);
  if (ticks >= keys[n - 1].mTime) return lerp(keys[n - 1].mValue, keys[n - 1].mValue, 0.0);
  unsigned i = 0;
  while (keys[i + 1].mTime <= ticks) ++i;
  return lerp(keys[i].mValue, keys[i + 1].mValue,
              (ticks - keys[i].mTime) / (keys[i + 1].mTime - keys[i].mTime));
}

Eigen::Vector3d lerp3(const aiVector3D& a, const aiVector3D& b, double t) {
  return (1 - t) * Eigen::Vector3d(a.x, a.y, a.z) + t * Eigen::Vector3d(b.x, b.y, b.z);
}

Eigen::Quaterniond nlerp(const aiQuaternion& a, const aiQuaternion& b, double t) {
  Eigen::Vector4d qa(a.w, a.x, a.y, a.z), qb(b.w, b.x, b.y, b.z);
  qa.normalize(), qb.normalize();
  if (qa.dot(qb) < 0) qb = -qb;
  const Eigen::Vector4d q = ((1 - t) * qa + t * qb).normalized();
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
}

// Node transforms of the scene at a time of one animation (−1: every node's own transform).
struct ScenePose {
  const aiScene& scene;
  std::map<const aiNode*, const aiNodeAnim*> channels;
  std::map<const aiNode*, Eigen::Matrix4d> global;

  ScenePose(const aiScene& s, int anim, double ticks) : scene(s) {
    std::map<std::string, const aiNode*> by_name;
    std::function<void(const aiNode*)> names = [&](const aiNode* n) {
      by_name.emplace(n->mName.C_Str(), n);
      for (unsigned c = 0; c < n->mNumChildren; ++c) names(n->mChildren[c]);
    };
    names(s.mRootNode);
    if (anim >= 0)
      for (unsigned c = 0; c < s.mAnimations[anim]->mNumChannels; ++c) {
        const aiNodeAnim* ch = s.mAnimations[anim]->mChannels[c];
        const auto it = by_name.find(ch->mNodeName.C_Str());
        if (it != by_name.end()) channels.emplace(it->second, ch);
      }
    // Globals along mParent (which assimp's HL1 MDL loader sets right where its children
    // lists are flat), as the importer does.
    std::function<Eigen::Matrix4d(const aiNode*)> up = [&](const aiNode* n) -> Eigen::Matrix4d {
      if (!n) return Eigen::Matrix4d::Identity();
      const auto it = global.find(n);
      if (it != global.end()) return it->second;
      const Eigen::Matrix4d g = up(n->mParent) * local(n, ticks);
      global.emplace(n, g);
      return g;
    };
    std::function<void(const aiNode*)> walk = [&](const aiNode* n) {
      up(n);
      for (unsigned c = 0; c < n->mNumChildren; ++c) walk(n->mChildren[c]);
    };
    walk(s.mRootNode);
  }

  Eigen::Matrix4d local(const aiNode* n, double ticks) const {
    const auto it = channels.find(n);
    if (it == channels.end()) return to_eigen(n->mTransformation);
    const aiNodeAnim* ch = it->second;
    aiVector3D s0, p0;
    aiQuaternion q0;
    n->mTransformation.Decompose(s0, q0, p0);
    const Eigen::Vector3d p = ch->mNumPositionKeys
                                  ? track(ch->mPositionKeys, ch->mNumPositionKeys, ticks, lerp3)
                                  : lerp3(p0, p0, 0);
    const Eigen::Quaterniond q = ch->mNumRotationKeys
                                     ? track(ch->mRotationKeys, ch->mNumRotationKeys, ticks, nlerp)
                                     : nlerp(q0, q0, 0);
    const Eigen::Vector3d sc = ch->mNumScalingKeys
                                   ? track(ch->mScalingKeys, ch->mNumScalingKeys, ticks, lerp3)
                                   : lerp3(s0, s0, 0);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = q.toRotationMatrix() * sc.asDiagonal();
    m.topRightCorner<3, 1>() = p;
    return m;
  }
};

// Matrix skinning of every instance's file vertices at one scene pose.
Eigen::Matrix3Xd matrix_skinning(const aiScene& scene, const ScenePose& pose,
                                 const std::vector<MeshInstance>& instances, Eigen::Index nv) {
  std::map<std::string, const aiNode*> by_name;
  for (const auto& [node, g] : pose.global) by_name.emplace(node->mName.C_Str(), node);
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, nv);
  for (const auto& in : instances) {
    const aiMesh* am = scene.mMeshes[in.mesh];
    std::vector<Eigen::Matrix4d> acc(am->mNumVertices, Eigen::Matrix4d::Zero());
    std::vector<double> sum(am->mNumVertices, 0);
    if (am->mNumBones == 0) {
      const Eigen::Matrix4d g = in.node ? pose.global.at(in.node) : Eigen::Matrix4d::Identity();
      std::fill(acc.begin(), acc.end(), g);
      std::fill(sum.begin(), sum.end(), 1.0);
    }
    for (unsigned b = 0; b < am->mNumBones; ++b) {
      const aiBone* bone = am->mBones[b];
      const auto it = by_name.find(bone->mName.C_Str());
      const Eigen::Matrix4d s =
          it == by_name.end()
              ? Eigen::Matrix4d::Identity()
              : Eigen::Matrix4d(pose.global.at(it->second) * to_eigen(bone->mOffsetMatrix));
      for (unsigned k = 0; k < bone->mNumWeights; ++k) {
        const aiVertexWeight& w = bone->mWeights[k];
        if (w.mWeight > 0) acc[w.mVertexId] += w.mWeight * s, sum[w.mVertexId] += w.mWeight;
      }
    }
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const Eigen::Vector4d x(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z, 1);
      out.col(in.first_vertex + static_cast<Eigen::Index>(v)) =
          (acc[v] * x).head<3>() / (sum[v] > 0 ? sum[v] : 1.0);
    }
  }
  return out;
}

}  // namespace

SkinningError skinning_error(const aiScene& scene, const SkinnedModel& model,
                             const std::vector<MeshInstance>& instances) {
  SkinningError e;
  const Eigen::Index nv = model.mesh.vertex_count();
  // Every influence, as matrix skinning uses them all.
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences,
                                std::max(1, model.influences.max_per_vertex()));
  Eigen::Matrix3Xd got;
  const auto compare = [&](const Eigen::Matrix3Xd& expected, const std::string& where) {
    skinner.write(got);
    const double d = (got - expected).colwise().norm().maxCoeff();
    if (d > e.worst) e.worst = d, e.where = where;
  };
  const Eigen::Matrix3Xd bind = matrix_skinning(scene, ScenePose(scene, -1, 0), instances, nv);
  e.diagonal = (bind.rowwise().maxCoeff() - bind.rowwise().minCoeff()).norm();
  skinner.skin(skin::Pose::rest(model.skeleton), skin::SkinMode::cga);
  compare(bind, "the rest pose");
  skin::Pose pose;
  for (std::size_t a = 0; a < model.animations.size(); ++a) {
    const auto& anim = model.animations[a];
    for (const double t : anim.key_times()) {
      anim.sample(model.skeleton, t, skin::Blend::linear, pose);
      skinner.skin(pose, skin::SkinMode::cga);
      std::ostringstream where;
      where << "animation '" << anim.name << "' at t = " << t << " s";
      compare(
          matrix_skinning(scene, ScenePose(scene, static_cast<int>(a), t * anim.ticks_per_second),
                          instances, nv),
          where.str());
    }
  }
  return e;
}

}  // namespace conform::io::detail
