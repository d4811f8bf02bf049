#include "conform/io/mesh_export.hpp"

#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <bit>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace conform::io {

MeshFormat parse_mesh_format(std::string_view name) {
  if (name == "ply") return MeshFormat::PlyBinary;
  if (name == "ply-ascii") return MeshFormat::PlyAscii;
  if (name == "obj") return MeshFormat::Obj;
  throw std::invalid_argument("unknown mesh format '" + std::string(name) +
                              "' (expected ply, ply-ascii or obj)");
}

const char* mesh_format_extension(MeshFormat format) {
  return format == MeshFormat::Obj ? ".obj" : ".ply";
}

namespace {

// The vertices and faces to write, renumbered when a face subset is given.
struct Selection {
  std::vector<std::int32_t> vertices;  // old index of each written vertex
  std::vector<mesh::Face> faces;       // in the new numbering
  std::vector<std::int32_t> face_ids;  // the mesh face of each written face
  // Per written vertex, when the mesh has corner attributes (split_wedges); else empty.
  Eigen::Matrix2Xd uvs;
  Eigen::Matrix3Xd normals;
};

Selection select(const mesh::SkinnedMesh& mesh, std::span<const std::int32_t> faces) {
  const std::int32_t nv = mesh.vertex_count();
  Selection s;
  auto check_face = [&](const mesh::Face& f) {
    for (auto v : f)
      if (v < 0 || v >= nv) throw std::out_of_range("mesh export: vertex index out of range");
  };
  if (faces.empty()) {
    s.vertices.resize(static_cast<std::size_t>(nv));
    for (std::int32_t i = 0; i < nv; ++i) s.vertices[static_cast<std::size_t>(i)] = i;
    s.faces = mesh.faces;
    s.face_ids.resize(mesh.faces.size());
    for (std::size_t f = 0; f < s.faces.size(); ++f) s.face_ids[f] = std::int32_t(f);
    for (const auto& f : s.faces) check_face(f);
    return s;
  }
  std::vector<std::int32_t> remap(static_cast<std::size_t>(nv), -1);
  std::vector<char> used(static_cast<std::size_t>(nv), 0);
  for (auto fi : faces) {
    if (fi < 0 || fi >= mesh.face_count())
      throw std::out_of_range("mesh export: face index out of range");
    const auto& f = mesh.faces[static_cast<std::size_t>(fi)];
    check_face(f);
    for (auto v : f) used[static_cast<std::size_t>(v)] = 1;
  }
  // Increasing old order keeps the output deterministic and independent of the face order.
  for (std::int32_t i = 0; i < nv; ++i)
    if (used[static_cast<std::size_t>(i)]) {
      remap[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(s.vertices.size());
      s.vertices.push_back(i);
    }
  s.faces.reserve(faces.size());
  s.face_ids.assign(faces.begin(), faces.end());
  for (auto fi : faces) {
    const auto& f = mesh.faces[static_cast<std::size_t>(fi)];
    s.faces.push_back({remap[static_cast<std::size_t>(f[0])], remap[static_cast<std::size_t>(f[1])],
                       remap[static_cast<std::size_t>(f[2])]});
  }
  return s;
}

// A welded mesh's seams written back: one written vertex per distinct (vertex, corner UV,
// corner normal), numbered in order of first use by the faces' corners.
void split_wedges(const mesh::SkinnedMesh& mesh, Selection& s) {
  const bool uvs = mesh.has_corner_uvs(), normals = mesh.has_corner_normals();
  if (!uvs && !normals) return;
  struct Wedge {
    std::int32_t vertex;
    std::array<double, 5> value;
    bool operator<(const Wedge& o) const {
      return vertex != o.vertex ? vertex < o.vertex : value < o.value;
    }
  };
  std::map<Wedge, std::int32_t> index;
  std::vector<std::int32_t> vertices;
  std::vector<Wedge> wedges;
  for (std::size_t i = 0; i < s.faces.size(); ++i) {
    const auto f = static_cast<Eigen::Index>(s.face_ids[i]);
    for (int k = 0; k < 3; ++k) {
      Wedge w{s.vertices[std::size_t(s.faces[i][std::size_t(k)])], {0, 0, 0, 0, 0}};
      for (int j = 0; uvs && j < 2; ++j) w.value[std::size_t(j)] = mesh.corner_uvs(2 * k + j, f);
      for (int j = 0; normals && j < 3; ++j)
        w.value[std::size_t(2 + j)] = mesh.corner_normals(3 * k + j, f);
      const auto [it, fresh] = index.try_emplace(w, std::int32_t(wedges.size()));
      if (fresh) wedges.push_back(w);
      s.faces[i][std::size_t(k)] = it->second;
    }
  }
  s.vertices.resize(wedges.size());
  if (uvs) s.uvs.resize(2, Eigen::Index(wedges.size()));
  if (normals) s.normals.resize(3, Eigen::Index(wedges.size()));
  for (std::size_t i = 0; i < wedges.size(); ++i) {
    s.vertices[i] = wedges[i].vertex;
    const auto c = static_cast<Eigen::Index>(i);
    if (uvs) s.uvs.col(c) << wedges[i].value[0], wedges[i].value[1];
    if (normals) s.normals.col(c) << wedges[i].value[2], wedges[i].value[3], wedges[i].value[4];
  }
}

template <class T>
void put(std::string& out, T value) {
  static_assert(std::endian::native == std::endian::little, "PLY writer assumes little-endian");
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Appends " %.17g" (or without the leading space). Piecewise appends also avoid GCC 12's
// false -Wrestrict on `" " + std::string`.
void add(std::string& out, double v, bool space = true) {
  char buf[40];
  const int n = std::snprintf(buf, sizeof buf, space ? " %.17g" : "%.17g", v);
  out.append(buf, static_cast<std::size_t>(n));
}

// What each written vertex carries: UVs and normals of its corner (a welded mesh) or of the
// vertex; normals only from corner normals (a mesh without seams writes none, as before).
struct Attributes {
  const mesh::SkinnedMesh& mesh;
  const Selection& s;
  bool uvs, normals, tags;
  Attributes(const mesh::SkinnedMesh& m, const Selection& sel, const MeshExportOptions& o)
      : mesh(m),
        s(sel),
        uvs(o.uvs && (sel.uvs.cols() > 0 || m.has_uvs())),
        normals(o.normals && sel.normals.cols() > 0),
        tags(o.face_tags && m.has_face_tags()) {}
  double uv(std::size_t i, int k) const {
    return s.uvs.cols() > 0 ? s.uvs(k, Eigen::Index(i)) : mesh.uvs(k, s.vertices[i]);
  }
  double normal(std::size_t i, int k) const { return s.normals(k, Eigen::Index(i)); }
};

std::string encode_obj(const Eigen::Ref<const Eigen::Matrix3Xd>& pos, const Attributes& a) {
  std::string out = "# conform mesh export\n";
  const auto& s = a.s;
  for (auto v : s.vertices) {
    out += "v";
    for (int k = 0; k < 3; ++k) add(out, pos(k, v));
    out += "\n";
  }
  for (std::size_t i = 0; a.uvs && i < s.vertices.size(); ++i)
    out += "vt", add(out, a.uv(i, 0)), add(out, a.uv(i, 1)), out += "\n";
  for (std::size_t i = 0; a.normals && i < s.vertices.size(); ++i)
    out += "vn", add(out, a.normal(i, 0)), add(out, a.normal(i, 1)), add(out, a.normal(i, 2)),
        out += "\n";
  for (const auto& f : s.faces) {
    out += "f";
    for (auto v : f) {
      const std::string i = std::to_string(v + 1);
      out.append(" ").append(i);
      if (a.uvs || a.normals) out.append("/");
      if (a.uvs) out.append(i);
      if (a.normals) out.append("/").append(i);
    }
    out += "\n";
  }
  return out;
}

std::string encode_ply(const Eigen::Ref<const Eigen::Matrix3Xd>& pos, const Attributes& a,
                       bool binary) {
  const auto& s = a.s;
  std::string out = "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment conform mesh export\n";
  out += "element vertex " + std::to_string(s.vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (a.uvs) out += "property double s\nproperty double t\n";
  if (a.normals) out += "property double nx\nproperty double ny\nproperty double nz\n";
  out += "element face " + std::to_string(s.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\n";
  if (a.tags) out += "property uchar surface\nproperty uint op\nproperty uchar edit\n";
  out += "end_header\n";
  for (std::size_t i = 0; i < s.vertices.size(); ++i) {
    std::array<double, 8> values{};
    int n = 0;
    for (int k = 0; k < 3; ++k) values[std::size_t(n++)] = pos(k, s.vertices[i]);
    for (int k = 0; a.uvs && k < 2; ++k) values[std::size_t(n++)] = a.uv(i, k);
    for (int k = 0; a.normals && k < 3; ++k) values[std::size_t(n++)] = a.normal(i, k);
    for (int k = 0; k < n; ++k)
      binary ? put(out, values[std::size_t(k)]) : add(out, values[std::size_t(k)], k > 0);
    if (!binary) out += "\n";
  }
  for (std::size_t i = 0; i < s.faces.size(); ++i) {
    const auto& f = s.faces[i];
    const mesh::FaceTag tag = a.tags ? a.mesh.face_tag(s.face_ids[i]) : mesh::FaceTag{};
    if (binary) {
      put(out, static_cast<std::uint8_t>(3));
      for (auto v : f) put(out, static_cast<std::int32_t>(v));
      if (a.tags)
        put(out, static_cast<std::uint8_t>(tag.kind)), put(out, tag.op),
            put(out, static_cast<std::uint8_t>(tag.edit));
    } else {
      // Appended piecewise: GCC 12 reports a false -Wrestrict on "3 " + std::string.
      out += "3";
      for (auto v : f) out.append(" ").append(std::to_string(v));
      if (a.tags)
        out.append(" ")
            .append(std::to_string(static_cast<int>(tag.kind)))
            .append(" ")
            .append(std::to_string(tag.op))
            .append(" ")
            .append(std::to_string(static_cast<int>(tag.edit)));
      out += "\n";
    }
  }
  return out;
}

// Finite or refused: a reader takes nan or inf in a file for a valid coordinate (or fails).
void check_finite(const Eigen::Matrix3Xd& pos, const Selection& s) {
  for (const std::int32_t v : s.vertices)
    if (!pos.col(v).allFinite()) {
      std::ostringstream why;
      why << "mesh export: vertex " << v << " is not finite (" << pos(0, v) << ", " << pos(1, v)
          << ", " << pos(2, v) << "); nothing written";
      throw std::runtime_error(why.str());
    }
  if (!s.uvs.allFinite() || !s.normals.allFinite())
    throw std::runtime_error("mesh export: a corner UV or normal is not finite; nothing written");
}

std::string encode(const mesh::SkinnedMesh& mesh, const Selection& s, const MeshExportOptions& o) {
  const auto& pos = o.rest_positions ? mesh.rest : mesh.current;
  if (pos.cols() != mesh.vertex_count())
    throw std::runtime_error("mesh export: position matrix does not match the vertex count");
  check_finite(pos, s);
  const Attributes attributes(mesh, s, o);
  if (o.format == MeshFormat::Obj) return encode_obj(pos, attributes);
  return encode_ply(pos, attributes, o.format == MeshFormat::PlyBinary);
}

}  // namespace

std::size_t mesh_file_size(const mesh::SkinnedMesh& mesh, const MeshExportOptions& options,
                           std::span<const std::int32_t> faces) {
  Selection selection = select(mesh, faces);
  split_wedges(mesh, selection);
  return encode(mesh, selection, options).size();
}

void write_mesh(const std::filesystem::path& path, const mesh::SkinnedMesh& mesh,
                const MeshExportOptions& options, std::span<const std::int32_t> faces) {
  Selection selection = select(mesh, faces);
  split_wedges(mesh, selection);
  const std::string data = encode(mesh, selection, options);
  // A unique temporary name in the target's directory, so that rename() is atomic.
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error("mesh export: cannot open " + tmp.string() + " for writing");
    os.write(data.data(), static_cast<std::streamsize>(data.size()));
    os.flush();
    if (!os) {
      os.close();
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error("mesh export: write to " + tmp.string() + " failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("mesh export: cannot rename " + tmp.string() + " to " + path.string() +
                             ": " + ec.message());
  }
}

}  // namespace conform::io
