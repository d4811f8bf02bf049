#include "conform/io/model_wire.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace conform::io {
namespace {

constexpr std::uint32_t kMagic = 0x434d5732;  // "CMW2": with the unit scale

class Writer {
 public:
  template <class T>
  void pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void count(std::size_t n) { pod(static_cast<std::uint64_t>(n)); }
  void str(const std::string& s) {
    count(s.size());
    out_.append(s);
  }
  template <class T>
  void pods(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    count(v.size());
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  template <class S, int R>
  void columns(const mesh::ColumnArray<S, R>& a) {
    count(static_cast<std::size_t>(a.cols()));
    out_.append(reinterpret_cast<const char*>(a.data()),
                static_cast<std::size_t>(a.cols()) * R * sizeof(S));
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <class T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof value), sizeof value);
    return value;
  }
  // A count of items of `item_bytes` each, checked against what is left.
  std::size_t count(std::size_t item_bytes) {
    const auto n = pod<std::uint64_t>();
    if (item_bytes > 0 && n > (in_.size() - at_) / item_bytes) fail("a count exceeds the message");
    return static_cast<std::size_t>(n);
  }
  std::string str() {
    const std::size_t n = count(1);
    return std::string(take(n), n);
  }
  template <class T>
  std::vector<T> pods() {
    const std::size_t n = count(sizeof(T));
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  template <class S, int R>
  void columns(mesh::ColumnArray<S, R>& a) {
    const std::size_t n = count(R * sizeof(S));
    a.resize(R, static_cast<Eigen::Index>(n));
    if (n) std::memcpy(a.data(), take(n * R * sizeof(S)), n * R * sizeof(S));
  }
  bool done() const { return at_ == in_.size(); }
  [[noreturn]] static void fail(const std::string& why) {
    throw std::runtime_error("model message: " + why);
  }

 private:
  const char* take(std::size_t n) {
    if (n > in_.size() - at_) fail("truncated");
    const char* p = in_.data() + at_;
    at_ += n;
    return p;
  }
  std::string_view in_;
  std::size_t at_ = 0;
};

void write_mesh(Writer& w, const mesh::SkinnedMesh& m) {
  w.columns(m.rest);
  w.columns(m.current);
  w.pods(m.faces);
  w.columns(m.bones);
  w.columns(m.weights);
  w.columns(m.uvs);
  w.columns(m.normals);
  w.columns(m.corner_uvs);
  w.columns(m.corner_normals);
}

void read_mesh(Reader& r, mesh::SkinnedMesh& m) {
  r.columns(m.rest);
  r.columns(m.current);
  m.faces = r.pods<mesh::Face>();
  r.columns(m.bones);
  r.columns(m.weights);
  r.columns(m.uvs);
  r.columns(m.normals);
  r.columns(m.corner_uvs);
  r.columns(m.corner_normals);
}

void write_skeleton(Writer& w, const skin::Skeleton& s) {
  static_assert(std::is_trivially_copyable_v<skin::Versor>);
  w.count(s.joints.size());
  for (const auto& j : s.joints) {
    w.str(j.name);
    w.pod(j.parent);
    w.pod(j.rest);
  }
  w.count(s.bones.size());
  for (const auto& b : s.bones) {
    w.str(b.name);
    w.pod(b.joint);
    w.pod(b.offset);
  }
}

void read_skeleton(Reader& r, skin::Skeleton& s) {
  s.joints.resize(r.count(sizeof(std::uint64_t)));
  for (auto& j : s.joints) {
    j.name = r.str();
    j.parent = r.pod<std::int32_t>();
    j.rest = r.pod<skin::Versor>();
  }
  s.bones.resize(r.count(sizeof(std::uint64_t)));
  for (auto& b : s.bones) {
    b.name = r.str();
    b.joint = r.pod<std::int32_t>();
    b.offset = r.pod<skin::Versor>();
  }
}

// Keys as plain numbers: Eigen's fixed types are not trivially copyable by the standard's rule.
template <class V, int N, class Get>
void write_keys(Writer& w, const std::vector<skin::Key<V>>& keys, Get coefficients) {
  w.count(keys.size());
  for (const auto& k : keys) {
    w.pod(k.time);
    const std::array<double, N> c = coefficients(k.value);
    w.pod(c);
  }
}

template <class V, int N, class Make>
std::vector<skin::Key<V>> read_keys(Reader& r, Make make) {
  std::vector<skin::Key<V>> keys(r.count(sizeof(double) * (N + 1)));
  for (auto& k : keys) {
    k.time = r.pod<double>();
    k.value = make(r.pod<std::array<double, N>>());
  }
  return keys;
}

void write_animation(Writer& w, const skin::Animation& a) {
  w.str(a.name);
  w.pod(a.duration_ticks);
  w.pod(a.ticks_per_second);
  w.count(a.channels.size());
  for (const auto& c : a.channels) {
    w.pod(c.joint);
    write_keys<Eigen::Vector3d, 3>(w, c.translation, [](const Eigen::Vector3d& t) {
      return std::array<double, 3>{t.x(), t.y(), t.z()};
    });
    write_keys<Eigen::Quaterniond, 4>(w, c.rotation, [](const Eigen::Quaterniond& q) {
      return std::array<double, 4>{q.w(), q.x(), q.y(), q.z()};
    });
    write_keys<double, 1>(w, c.scale, [](double s) { return std::array<double, 1>{s}; });
  }
}

skin::Animation read_animation(Reader& r) {
  skin::Animation a;
  a.name = r.str();
  a.duration_ticks = r.pod<double>();
  a.ticks_per_second = r.pod<double>();
  a.channels.resize(r.count(sizeof(std::int32_t)));
  for (auto& c : a.channels) {
    c.joint = r.pod<std::int32_t>();
    c.translation = read_keys<Eigen::Vector3d, 3>(
        r, [](const std::array<double, 3>& v) { return Eigen::Vector3d(v[0], v[1], v[2]); });
    c.rotation = read_keys<Eigen::Quaterniond, 4>(r, [](const std::array<double, 4>& v) {
      return Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
    });
    c.scale = read_keys<double, 1>(r, [](const std::array<double, 1>& v) { return v[0]; });
  }
  return a;
}

void write_info(Writer& w, const MeshInfo& m) {
  w.str(m.name);
  w.pod(std::array<std::int32_t, 7>{m.first_vertex, m.vertex_count, m.first_face, m.face_count,
                                    m.joint, m.bones, m.source});
}

MeshInfo read_info(Reader& r) {
  MeshInfo m;
  m.name = r.str();
  const auto v = r.pod<std::array<std::int32_t, 7>>();
  m.first_vertex = v[0];
  m.vertex_count = v[1];
  m.first_face = v[2];
  m.face_count = v[3];
  m.joint = v[4];
  m.bones = v[5];
  m.source = v[6];
  return m;
}

}  // namespace

std::string encode_model(const SkinnedModel& model) {
  Writer w;
  w.pod(kMagic);
  w.str(model.source);
  w.pod(model.unit_scale_cm);
  write_mesh(w, model.mesh);
  w.pods(model.influences.offsets);
  w.pods(model.influences.bones);
  w.pods(model.influences.weights);
  write_skeleton(w, model.skeleton);
  w.count(model.animations.size());
  for (const auto& a : model.animations) write_animation(w, a);
  w.count(model.meshes.size());
  for (const auto& m : model.meshes) write_info(w, m);
  w.count(model.warnings.size());
  for (const auto& s : model.warnings) w.str(s);
  return w.take();
}

SkinnedModel decode_model(std::string_view bytes) {
  Reader r(bytes);
  if (r.pod<std::uint32_t>() != kMagic) Reader::fail("not a model message");
  SkinnedModel model;
  model.source = r.str();
  model.unit_scale_cm = r.pod<double>();
  if (!(std::isfinite(model.unit_scale_cm) && model.unit_scale_cm >= 0))
    Reader::fail("a unit scale that is not a finite number >= 0");
  read_mesh(r, model.mesh);
  model.influences.offsets = r.pods<std::int32_t>();
  model.influences.bones = r.pods<std::int32_t>();
  model.influences.weights = r.pods<double>();
  read_skeleton(r, model.skeleton);
  const std::size_t animations = r.count(sizeof(std::uint64_t));
  for (std::size_t i = 0; i < animations; ++i) model.animations.push_back(read_animation(r));
  const std::size_t meshes = r.count(sizeof(std::uint64_t));
  for (std::size_t i = 0; i < meshes; ++i) model.meshes.push_back(read_info(r));
  model.warnings.resize(r.count(sizeof(std::uint64_t)));
  for (auto& s : model.warnings) s = r.str();
  if (!r.done()) Reader::fail("bytes left over");
  return model;
}

}  // namespace conform::io
