#include "conform/io/mesh_export.hpp"

#include <unistd.h>

#include <atomic>
#include <bit>
#include <cstdio>
#include <cstring>
#include <fstream>
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
  for (auto fi : faces) {
    const auto& f = mesh.faces[static_cast<std::size_t>(fi)];
    s.faces.push_back({remap[static_cast<std::size_t>(f[0])], remap[static_cast<std::size_t>(f[1])],
                       remap[static_cast<std::size_t>(f[2])]});
  }
  return s;
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

std::string encode(const mesh::SkinnedMesh& mesh, const Selection& s, const MeshExportOptions& o) {
  const auto& pos = o.rest_positions ? mesh.rest : mesh.current;
  if (pos.cols() != mesh.vertex_count())
    throw std::runtime_error("mesh export: position matrix does not match the vertex count");
  const bool uvs = o.uvs && mesh.has_uvs();
  std::string out;
  if (o.format == MeshFormat::Obj) {
    out += "# conform mesh export\n";
    for (auto v : s.vertices) {
      out += "v";
      for (int k = 0; k < 3; ++k) add(out, pos(k, v));
      out += "\n";
    }
    if (uvs)
      for (auto v : s.vertices)
        out += "vt", add(out, mesh.uvs(0, v)), add(out, mesh.uvs(1, v)), out += "\n";
    for (const auto& f : s.faces) {
      out += "f";
      for (auto v : f) {
        const std::string i = std::to_string(v + 1);
        out.append(" ").append(i);
        if (uvs) out.append("/").append(i);
      }
      out += "\n";
    }
    return out;
  }
  const bool binary = o.format == MeshFormat::PlyBinary;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment conform mesh export\n";
  out += "element vertex " + std::to_string(s.vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (uvs) out += "property double s\nproperty double t\n";
  out += "element face " + std::to_string(s.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (auto v : s.vertices) {
    if (binary) {
      for (int k = 0; k < 3; ++k) put(out, pos(k, v));
      if (uvs) put(out, mesh.uvs(0, v)), put(out, mesh.uvs(1, v));
    } else {
      add(out, pos(0, v), false), add(out, pos(1, v)), add(out, pos(2, v));
      if (uvs) add(out, mesh.uvs(0, v)), add(out, mesh.uvs(1, v));
      out += "\n";
    }
  }
  for (const auto& f : s.faces) {
    if (binary) {
      put(out, static_cast<std::uint8_t>(3));
      for (auto v : f) put(out, static_cast<std::int32_t>(v));
    } else {
      // Appended piecewise: GCC 12 reports a false -Wrestrict on "3 " + std::string.
      out += "3";
      for (auto v : f) out.append(" ").append(std::to_string(v));
      out += "\n";
    }
  }
  return out;
}

}  // namespace

void write_mesh(const std::filesystem::path& path, const mesh::SkinnedMesh& mesh,
                const MeshExportOptions& options, std::span<const std::int32_t> faces) {
  const std::string data = encode(mesh, select(mesh, faces), options);
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
