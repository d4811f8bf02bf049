#include "gltf_sequence.hpp"

#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <map>
#include <stdexcept>

#include "colour_scale.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

void GltfSequence::add(FrameSnapshot frame) {
  for (auto& f : frames_)
    if (f.name == frame.name && f.step == frame.step) {
      f = std::move(frame);
      return;
    }
  frames_.push_back(std::move(frame));
}

namespace {

aiMesh* to_mesh(const FrameSnapshot& f, const ColourScale& scale) {
  auto* m = new aiMesh;
  m->mName = f.name + "_" + std::to_string(f.step);
  m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  const auto nv = static_cast<unsigned>(f.positions.cols());
  m->mNumVertices = nv;
  m->mVertices = new aiVector3D[nv];
  m->mNormals = new aiVector3D[nv];
  m->mTextureCoords[0] = new aiVector3D[nv];
  m->mNumUVComponents[0] = 2;
  m->mColors[0] = new aiColor4D[nv];
  for (unsigned v = 0; v < nv; ++v) {
    const auto x = f.positions.col(v), n = f.normals.col(v);
    m->mVertices[v] = aiVector3D(ai_real(x.x()), ai_real(x.y()), ai_real(x.z()));
    m->mNormals[v] = aiVector3D(ai_real(n.x()), ai_real(n.y()), ai_real(n.z()));
    m->mTextureCoords[0][v] = aiVector3D(ai_real(f.uvs(0, v)), ai_real(f.uvs(1, v)), 0);
    const Rgb c = scale(f.scalar[v]);
    m->mColors[0][v] = aiColor4D(ai_real(c[0]), ai_real(c[1]), ai_real(c[2]), 1);
  }
  m->mNumFaces = static_cast<unsigned>(f.faces.size());
  m->mFaces = new aiFace[m->mNumFaces];
  for (unsigned i = 0; i < m->mNumFaces; ++i) {
    aiFace& face = m->mFaces[i];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k)
      face.mIndices[k] = static_cast<unsigned>(f.faces[i][static_cast<std::size_t>(k)]);
  }
  m->mMaterialIndex = 0;
  return m;
}

// Scale keys that show a node over [from, to) and hide it otherwise; `to` < 0: to the end.
// glTF's key times must increase strictly, so a step is two keys kEpsilon apart.
aiNodeAnim* visibility(const std::string& node, double from, double to) {
  constexpr double kEpsilon = 1e-4;  // s
  std::vector<std::pair<double, double>> keys;
  if (from > 2 * kEpsilon) keys.push_back({0, 0}), keys.push_back({from - kEpsilon, 0});
  keys.push_back({from, 1});
  if (to > from + 2 * kEpsilon) keys.push_back({to - kEpsilon, 1}), keys.push_back({to, 0});
  auto* ch = new aiNodeAnim;
  ch->mNodeName = node;
  ch->mNumScalingKeys = static_cast<unsigned>(keys.size());
  ch->mScalingKeys = new aiVectorKey[keys.size()];
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const auto s = ai_real(keys[i].second);
    ch->mScalingKeys[i] = aiVectorKey(keys[i].first, aiVector3D(s, s, s));
  }
  // The exporter writes every kind of key it is given: one still position and rotation.
  ch->mNumPositionKeys = 1;
  ch->mPositionKeys = new aiVectorKey[1];
  ch->mNumRotationKeys = 1;
  ch->mRotationKeys = new aiQuatKey[1];
  return ch;
}

// One row per run name, side by side along x, each row 1.5 widths of the first row's mesh.
std::map<std::string, double> row_offsets(const std::vector<FrameSnapshot>& frames) {
  std::map<std::string, double> offsets;
  double width = 0;
  for (const auto& f : frames)
    if (f.positions.cols() > 0)
      width = std::max(width, f.positions.row(0).maxCoeff() - f.positions.row(0).minCoeff());
  for (const auto& f : frames)
    if (!offsets.count(f.name)) {
      const auto k = double(offsets.size());
      offsets[f.name] = k * 1.5 * width;
    }
  return offsets;
}

}  // namespace

void GltfSequence::write(const fs::path& path, const std::string& scalar, double range) const {
  if (frames_.empty()) return;
  std::vector<double> values;
  for (const auto& f : frames_) values.insert(values.end(), f.scalar.begin(), f.scalar.end());
  const ColourScale scale = make_scale(scalar, values, range);
  const auto offsets = row_offsets(frames_);
  aiScene scene;
  scene.mRootNode = new aiNode("conform_run");
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial };
  const aiString material_name("skin");
  scene.mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);
  const auto n = static_cast<unsigned>(frames_.size());
  scene.mNumMeshes = n;
  scene.mMeshes = new aiMesh*[n];
  scene.mRootNode->mNumChildren = n;
  scene.mRootNode->mChildren = new aiNode*[n];
  auto* anim = new aiAnimation;
  anim->mName = "sequence";
  anim->mTicksPerSecond = 1;  // key times in seconds
  anim->mNumChannels = n;
  anim->mChannels = new aiNodeAnim*[n];
  scene.mNumAnimations = 1;
  scene.mAnimations = new aiAnimation* [1] { anim };
  for (unsigned i = 0; i < n; ++i) {
    const FrameSnapshot& f = frames_[i];
    scene.mMeshes[i] = to_mesh(f, scale);
    auto* node = new aiNode(scene.mMeshes[i]->mName.C_Str());
    node->mParent = scene.mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{i};
    node->mTransformation = aiMatrix4x4::Translation(aiVector3D(ai_real(offsets.at(f.name)), 0, 0),
                                                     node->mTransformation);
    scene.mRootNode->mChildren[i] = node;
    // Shown from its own time until the next frame of the same run.
    double next = -1;
    for (const auto& g : frames_)
      if (g.name == f.name && g.time > f.time && (next < 0 || g.time < next)) next = g.time;
    anim->mChannels[i] = visibility(node->mName.C_Str(), f.time, next);
    anim->mChannels[i]->mPositionKeys[0] =
        aiVectorKey(f.time, aiVector3D(ai_real(offsets.at(f.name)), 0, 0));
    anim->mDuration = std::max(anim->mDuration, f.time);
  }
  const fs::path tmp = path.parent_path() / ("." + path.filename().string() + ".tmp");
  Assimp::Exporter exporter;
  if (exporter.Export(&scene, "glb2", tmp.string()) != aiReturn_SUCCESS) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path.string() + ": " + exporter.GetErrorString());
  }
  fs::rename(tmp, path);
}

}  // namespace conform::scenes
