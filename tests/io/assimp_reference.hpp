// Matrix skinning of a model file computed independently from assimp's own aiMatrix4x4 node
// and offset matrices, in double: the reference the import tests compare CGA skinning with.
// Every instance of a mesh is skinned (a mesh without bones follows each node that places
// it), in the importer's order: mesh by mesh, each mesh's instances in node order.
#pragma once

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <gtest/gtest.h>
#include <Eigen/LU>
#include <assimp/Importer.hpp>
#include <cmath>
#include <functional>
#include <map>
#include <vector>

#include "conform/io/import.hpp"
#include "conform/skin/baselines.hpp"

namespace conform::test {

using M4 = aiMatrix4x4t<double>;

inline M4 to_double(const aiMatrix4x4& m) {
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
inline M4 similar(const M4& m) {
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

inline aiQuaterniont<double> quat_interp(const aiQuaternion& qa, const aiQuaternion& qb, double a,
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

  // Every placed mesh: (mesh, node) mesh by mesh, each mesh's nodes in depth-first order; a
  // mesh no node places sits at the root.
  std::vector<std::pair<unsigned, const aiNode*>> placements() const {
    std::vector<std::pair<unsigned, const aiNode*>> out;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const auto before = out.size();
      std::function<void(const aiNode*)> find = [&](const aiNode* n) {
        for (unsigned i = 0; i < n->mNumMeshes; ++i)
          if (n->mMeshes[i] == m) out.push_back({m, n});
        for (unsigned c = 0; c < n->mNumChildren; ++c) find(n->mChildren[c]);
      };
      find(scene->mRootNode);
      if (out.size() == before) out.push_back({m, scene->mRootNode});
    }
    return out;
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
    const auto placed = placements();
    std::size_t nv = 0;
    for (const auto& [m, node] : placed) nv += scene->mMeshes[m]->mNumVertices;
    Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(nv));
    std::vector<Eigen::Matrix4d> mats;
    skin::InfluenceLists lists;
    std::vector<std::vector<std::pair<int, double>>> inf(nv);
    std::size_t base = 0;
    for (const auto& [m, owner] : placed) {
      const aiMesh* am = scene->mMeshes[m];
      if (am->mNumBones == 0) {
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
      for (const auto& [m, owner] : placed)
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

}  // namespace conform::test
