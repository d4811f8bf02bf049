#include "render/gltf_sequence.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

#include "render/colour_scale.hpp"

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

// The model being built: one buffer holding every array, a view and an accessor per array.
struct Builder {
  tinygltf::Model model;

  int view(const void* data, std::size_t bytes, int target) {
    auto& buf = model.buffers.front().data;
    while (buf.size() % 4) buf.push_back(0);  // accessors must be aligned to their component
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size() - 1);
  }

  // Floats, `width` per element (1, 2, 3 or 4); with bounds (required for POSITION and inputs).
  int floats(const std::vector<float>& data, int width, int target, bool bounds) {
    tinygltf::Accessor a;
    a.bufferView = view(data.data(), data.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = data.size() / static_cast<std::size_t>(width);
    a.type = width == 1   ? TINYGLTF_TYPE_SCALAR
             : width == 2 ? TINYGLTF_TYPE_VEC2
             : width == 3 ? TINYGLTF_TYPE_VEC3
                          : TINYGLTF_TYPE_VEC4;
    if (bounds && a.count > 0) {
      a.minValues.assign(static_cast<std::size_t>(width), 1e300);
      a.maxValues.assign(static_cast<std::size_t>(width), -1e300);
      for (std::size_t i = 0; i < data.size(); ++i) {
        auto& lo = a.minValues[i % static_cast<std::size_t>(width)];
        auto& hi = a.maxValues[i % static_cast<std::size_t>(width)];
        lo = std::min(lo, double(data[i]));
        hi = std::max(hi, double(data[i]));
      }
    }
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }

  int indices(const std::vector<std::uint32_t>& data) {
    tinygltf::Accessor a;
    a.bufferView = view(data.data(), data.size() * sizeof(std::uint32_t),
                        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = data.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }
};

int add_mesh(Builder& b, const FrameSnapshot& f, const ColourScale& scale) {
  const auto nv = static_cast<std::size_t>(f.positions.cols());
  std::vector<float> x(3 * nv), n(3 * nv), uv(2 * nv), c(4 * nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto i = static_cast<Eigen::Index>(v);
    for (int k = 0; k < 3; ++k) {
      x[3 * v + std::size_t(k)] = float(f.positions(k, i));
      n[3 * v + std::size_t(k)] = float(f.normals(k, i));
    }
    uv[2 * v] = float(f.uvs(0, i));
    uv[2 * v + 1] = float(f.uvs(1, i));
    const Rgb rgb = scale(f.scalar[v]);
    c[4 * v] = float(rgb[0]), c[4 * v + 1] = float(rgb[1]), c[4 * v + 2] = float(rgb[2]);
    c[4 * v + 3] = 1;
  }
  std::vector<std::uint32_t> idx;
  idx.reserve(3 * f.faces.size());
  for (const auto& face : f.faces)
    for (const auto v : face) idx.push_back(static_cast<std::uint32_t>(v));
  tinygltf::Primitive p;
  p.mode = TINYGLTF_MODE_TRIANGLES;
  p.material = 0;
  p.attributes["POSITION"] = b.floats(x, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
  p.attributes["NORMAL"] = b.floats(n, 3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
  p.attributes["TEXCOORD_0"] = b.floats(uv, 2, TINYGLTF_TARGET_ARRAY_BUFFER, false);
  p.attributes["COLOR_0"] = b.floats(c, 4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
  p.indices = b.indices(idx);
  tinygltf::Mesh m;
  char step[16];
  std::snprintf(step, sizeof step, "_%06d", f.step);
  m.name = f.name + step;  // as the PLY frame: frames/NAME_STEP.ply
  m.primitives.push_back(p);
  b.model.meshes.push_back(m);
  return static_cast<int>(b.model.meshes.size() - 1);
}

// STEP keys that show node `node` over [from, to) and hide it before and after (to < 0: shown
// to the end).
void add_visibility(Builder& b, tinygltf::Animation& anim, int node, double from, double to) {
  std::vector<float> times, scales;
  const auto key = [&](double t, float s) {
    times.push_back(float(t));
    scales.insert(scales.end(), {s, s, s});
  };
  if (from > 0) key(0, 0);
  key(from, 1);
  if (to > from) key(to, 0);
  tinygltf::AnimationSampler s;
  s.input = b.floats(times, 1, 0, true);
  s.output = b.floats(scales, 3, 0, false);
  s.interpolation = "STEP";
  anim.samplers.push_back(s);
  tinygltf::AnimationChannel ch;
  ch.sampler = static_cast<int>(anim.samplers.size() - 1);
  ch.target_node = node;
  ch.target_path = "scale";
  anim.channels.push_back(ch);
}

// One row per run name, side by side along x, each row 1.5 widths of the widest mesh.
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
  Builder b;
  b.model.asset.version = "2.0";
  b.model.asset.generator = "conform";
  b.model.buffers.resize(1);
  tinygltf::Material skin;
  skin.name = "skin";
  skin.doubleSided = true;  // through an open wound a viewer sees the skin's inside
  skin.pbrMetallicRoughness.metallicFactor = 0;
  skin.pbrMetallicRoughness.roughnessFactor = 0.8;
  b.model.materials.push_back(skin);
  tinygltf::Scene scene;
  tinygltf::Animation anim;
  anim.name = "sequence";
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    const FrameSnapshot& f = frames_[i];
    tinygltf::Node node;
    node.mesh = add_mesh(b, f, scale);
    node.name = b.model.meshes.back().name;
    node.translation = {offsets.at(f.name), 0, 0};
    b.model.nodes.push_back(node);
    const int id = static_cast<int>(b.model.nodes.size() - 1);
    scene.nodes.push_back(id);
    // Shown from its own time until the next frame of the same run.
    double next = -1;
    for (const auto& g : frames_)
      if (g.name == f.name && g.time > f.time && (next < 0 || g.time < next)) next = g.time;
    add_visibility(b, anim, id, f.time, next);
  }
  b.model.scenes.push_back(scene);
  b.model.defaultScene = 0;
  b.model.animations.push_back(anim);
  const fs::path tmp = path.parent_path() / ("." + path.filename().string() + ".tmp");
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(&b.model, tmp.string(), false, true, false, true)) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path.string() + " (tinygltf)");
  }
  fs::rename(tmp, path);
}

}  // namespace conform::scenes
