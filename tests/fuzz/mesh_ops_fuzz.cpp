// Fuzz target: cut planes, tear scalpel samples and drills on random geometry: the procedural
// arm (small ones and arm:1), a flat sheet (open, with a boundary) and a small real model
// (assimp-testmodels' simple_skin.gltf, when installed), whose positions the input may first
// spoil (NaN, huge, coincident with another vertex, on a face's opposite edge). Then up to four
// operations, each of a plane, blade or drill placed on the mesh's surface or anywhere (zero
// normals, coincident blade ends, huge and NaN coordinates included).
// Choices are read in a fixed order (never two reads in one expression's operands or a call's
// arguments, whose order GCC and clang choose differently), so that the GCC replay of an input
// does what the clang fuzzer did.
// Properties, after every operation (mesh::apply inside it):
//   - it refuses degenerate input with std::invalid_argument only (the documented refusal), and
//     a cut computes a change that validates before it is applied;
//   - the mesh's own invariants (mesh::check_mesh) hold: indices in range, no repeated vertex,
//     positions finite when they were, and no more overused or misoriented edges or
//     non-manifold vertices than before; every per-vertex and per-corner array has its size,
//     every new vertex finite rest position and weights summing to 1.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "conform/io/import.hpp"
#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "fuzz_bytes.hpp"

using namespace conform;
using fuzz::Bytes;
using fuzz::fuzz_require;
using mesh::SkinnedMesh;

namespace {

// The base meshes, each built once.
const SkinnedMesh& base_mesh(Bytes& in) {
  static std::map<int, SkinnedMesh> cache;
  const int kind = in.in(0, 3);
  int key = kind;
  if (kind == 0) {  // a small arm (reads in order: GCC and clang order operands differently)
    const int segments = in.in(3, 16);
    key = 1000 + segments * 32 + in.in(2, 21);
  }
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  SkinnedMesh m;
  if (kind == 0) {
    skin::ArmOptions o;
    o.segments = (key - 1000) / 32;
    o.rings = (key - 1000) % 32;
    m = skin::make_arm(o).mesh;
  } else if (kind == 1) {
    m = skin::make_arm(1).mesh;
  } else if (kind == 2) {
    m = mesh::make_sheet(6, 5, 0.2, 0.15);
  } else {
    const std::filesystem::path real =
        std::filesystem::path(CONFORM_ASSIMP_MODELS) / "glTF2/simple_skin/simple_skin.gltf";
    m = std::filesystem::exists(real) ? io::load_model(real.string()).mesh
                                      : mesh::make_icosphere(1, 0.1);
  }
  return cache.emplace(key, std::move(m)).first->second;
}

std::int32_t some_vertex(Bytes& in, const SkinnedMesh& m) {
  return static_cast<std::int32_t>(in.in(0, 65535) % m.vertex_count());
}

// Spoils up to three positions.
void perturb(Bytes& in, SkinnedMesh& m) {
  for (int n = in.in(0, 3); n > 0; --n) {
    const std::int32_t v = some_vertex(in, m);
    switch (in.in(0, 3)) {
      case 0: {
        const double value = in.number(-1, 1);  // first, as C++17 orders `a = b`
        m.current(in.in(0, 2), v) = value;
        break;
      }
      case 1:
        m.current.col(v) = m.current.col(some_vertex(in, m));
        break;   // coincident
      case 2: {  // onto the opposite edge of a face: a degenerate (zero-area) face
        const mesh::Face& f = m.faces[static_cast<std::size_t>(in.in(0, 65535)) % m.faces.size()];
        m.current.col(f[0]) = 0.5 * (m.current.col(f[1]) + m.current.col(f[2]));
        break;
      }
      default:
        m.current.col(v) *= in.number(1e3, 1e12);
        break;
    }
  }
}

// A point: on the surface (a face, barycentric), a vertex, in the bounding box, or special.
Eigen::Vector3d point(Bytes& in, const SkinnedMesh& m) {
  switch (in.in(0, 3)) {
    case 0: {
      const mesh::Face& f = m.faces[static_cast<std::size_t>(in.in(0, 65535)) % m.faces.size()];
      double a = in.unit(), b = in.unit();
      if (a + b > 1) a = 1 - a, b = 1 - b;
      return (1 - a - b) * m.current.col(f[0]) + a * m.current.col(f[1]) + b * m.current.col(f[2]);
    }
    case 1:
      return m.current.col(some_vertex(in, m));
    case 2: {
      const Eigen::Vector3d lo = m.current.rowwise().minCoeff(),
                            hi = m.current.rowwise().maxCoeff();
      const double x = in.unit(), y = in.unit(), z = in.unit();
      return lo + Eigen::Vector3d(x, y, z).cwiseProduct(hi - lo);
    }
    default:
      return {in.number(-1, 1), in.number(-1, 1), in.number(-1, 1)};
  }
}

Eigen::Vector3d direction(Bytes& in) {
  return {in.number(-1, 1), in.number(-1, 1), in.number(-1, 1)};  // zero and NaN included
}

void cut(Bytes& in, SkinnedMesh& m, mesh::Adjacency& adjacency) {
  const Eigen::Vector3d p = point(in, m), n = direction(in);
  cga::Plane<double> plane = cga::Plane<double>::from_normal_point(n, p);
  if (in.in(0, 7) == 0) plane.e1 = n.x(), plane.e2 = n.y(), plane.e3 = n.z();  // not unit
  mesh::CutOptions options;
  options.cap = in.in(0, 1) == 1;
  switch (in.in(0, 3)) {
    case 1:
      options.region = mesh::CutRegion::sphere(point(in, m), in.number(0, 0.2));
      break;
    case 2:
      options.region = mesh::CutRegion::seed(point(in, m));
      break;
    default:
      break;
  }
  const mesh::CutResult r = mesh::compute_cut(m, plane, options);
  if (r.status != mesh::CutStatus::Cut) return;
  const std::string problem = r.change.validate();
  fuzz_require(problem.empty(), "the cut computed an invalid change: " + problem);
  mesh::apply(m, r.change, &adjacency);
}

void tear(Bytes& in, SkinnedMesh& m, mesh::Adjacency& adjacency) {
  mesh::Tear tear(m, adjacency);
  const double size = mesh::bounding_diagonal(m);
  Eigen::Vector3d at = point(in, m), step = direction(in) * 0.05 * size;
  const Eigen::Vector3d across = direction(in) * 0.05 * size;
  for (int i = in.in(1, 6); i > 0; --i) {
    if (in.in(0, 7) == 0) at = point(in, m);  // a jump
    const Eigen::Vector3d a = at + across, b = in.in(0, 7) == 0 ? a : Eigen::Vector3d(at - across);
    (void)tear.advance({double(i), a, b});
    at += step;
  }
}

void drill(Bytes& in, SkinnedMesh& m, mesh::Adjacency& adjacency) {
  const double size = mesh::bounding_diagonal(m);
  const Eigen::Vector3d at = point(in, m), axis = direction(in) * size;
  mesh::DrillTool tool{at + axis, at - axis, in.number(0, 0.1) * size};
  if (in.in(0, 7) == 0) tool.base = tool.tip;  // A = B
  mesh::DrillOptions options;
  options.tube = in.in(0, 1) == 1;
  if (options.tube && in.in(0, 1) == 1) options.tube_ring_spacing = 1.5;
  (void)mesh::drill(m, adjacency, tool, options);
}

void expect_invariants(const SkinnedMesh& m, const mesh::MeshReport& before, bool finite,
                       std::int32_t old_vertices, const char* what) {
  const std::string op = std::string("after a ") + what + ": ";
  const Eigen::Index v = m.rest.cols(), f = m.face_count();
  fuzz_require(m.current.cols() == v && m.bones.cols() == v && m.weights.cols() == v &&
                   (m.uvs.cols() == v || m.uvs.cols() == 0) &&
                   (m.normals.cols() == v || m.normals.cols() == 0) &&
                   (m.corner_uvs.cols() == f || m.corner_uvs.cols() == 0) &&
                   (m.corner_normals.cols() == f || m.corner_normals.cols() == 0),
               op + "an attribute array has the wrong size");
  const mesh::MeshReport r = mesh::check_mesh(m);
  fuzz_require(r.indices_valid, op + "a face index out of range or repeated");
  fuzz_require(r.finite || !finite, op + "non-finite positions");
  fuzz_require(r.overused_edges <= before.overused_edges &&
                   r.misoriented_edges <= before.misoriented_edges &&
                   r.nonmanifold_vertices <= before.nonmanifold_vertices,
               op + "the mesh got less manifold: " + before.summary() + " -> " + r.summary());
  for (std::int32_t i = old_vertices; i < m.vertex_count(); ++i)
    fuzz_require(m.rest.col(i).allFinite() && std::abs(m.weights.col(i).sum() - 1) < 1e-9,
                 op + "new vertex " + std::to_string(i) + " has a bad rest position or weights");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  SkinnedMesh m = base_mesh(in);
  perturb(in, m);
  mesh::Adjacency adjacency(m);
  for (int n = in.in(1, 4); n > 0 && !in.empty() && !m.faces.empty(); --n) {
    const int op = in.in(0, 2);
    const char* what = op == 0 ? "cut" : op == 1 ? "tear" : "drill";
    const mesh::MeshReport before = mesh::check_mesh(m);
    const std::int32_t old_vertices = m.vertex_count();
    try {
      if (op == 0) cut(in, m, adjacency);
      if (op == 1) tear(in, m, adjacency);
      if (op == 2) drill(in, m, adjacency);
    } catch (const std::invalid_argument&) {
      // refused (degenerate input); the mesh must still be intact
    } catch (const std::exception& e) {
      fuzz_require(false, std::string("a ") + what + " threw a non-input error: " + e.what());
    }
    expect_invariants(m, before, before.finite, old_vertices, what);
  }
  return 0;
}
