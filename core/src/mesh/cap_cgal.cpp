// The CGAL path of triangulate_section (cap.hpp): the only translation unit of the library
// that includes CGAL, compiled with CONFORM_HAVE_CGAL when CMake found it (header-only use,
// with CGAL_DISABLE_GMP so that nothing needs linking).
#include "conform/mesh/cap.hpp"

#if CONFORM_HAVE_CGAL

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace conform::mesh::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<std::int32_t, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Loops must not cross or touch: any intersection of constraints throws.
using Cdt =
    CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;

}  // namespace

bool cdt_available() {
  return true;
}

namespace {

// Input conditioning. A cut section is often symmetric (a tube cut across: points on an
// ellipse, four of them on a rectangle and so exactly cocircular), and every exact tie of the
// in-circle predicate sends the filtered kernel into exact arithmetic (tens of µs each). The
// points are centred on their bounding box (smaller coordinates, tighter filter bounds) and
// sheared by x += kShear · y: a shear has determinant 1, so it keeps every orientation (the
// loops, their nesting and the constraint edges) while breaking the cocircularity of such
// symmetric sets, which the floating-point filter then decides. The triangulation is the
// constrained Delaunay one of the sheared points, i.e. of the section up to ties within
// ~kShear of the empty-circle criterion.
constexpr double kShear = 0x1p-32;  // ≈ 2e-10

bool triangulate(const std::vector<std::vector<Eigen::Vector2d>>& loops, bool condition,
                 SectionTriangulation& out) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  if (condition) {
    Eigen::Vector2d lo = loops[0][0], hi = loops[0][0];
    for (const auto& l : loops)
      for (const auto& q : l) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    centre = 0.5 * (lo + hi);
  }
  const double shear = condition ? kShear : 0.0;
  try {
    Cdt cdt;
    std::vector<std::vector<Cdt::Vertex_handle>> handles(loops.size());
    std::int32_t first_id = 0;
    for (std::size_t l = 0; l < loops.size(); ++l) {
      // Every point of a convex loop is outside the hull of the earlier ones: inserted in loop
      // order, each would see a long stretch of hull and restore Delaunay by many flips.
      // A stride of about n/φ, coprime with n, spreads the insertions around the loop.
      const auto n = static_cast<std::int64_t>(loops[l].size());
      std::int64_t stride = std::max<std::int64_t>(1, std::llround(0.618 * static_cast<double>(n)));
      while (std::gcd(stride, n) != 1) ++stride;
      handles[l].resize(loops[l].size());
      for (std::int64_t k = 0, i = 0; k < n; ++k, i = (i + stride) % n) {
        const Eigen::Vector2d q = loops[l][static_cast<std::size_t>(i)] - centre;
        const Cdt::Vertex_handle v = cdt.insert(K::Point_2(q.x() + shear * q.y(), q.y()));
        v->info() = first_id + static_cast<std::int32_t>(i);
        handles[l][static_cast<std::size_t>(i)] = v;
      }
      first_id += static_cast<std::int32_t>(n);
    }
    const std::int32_t id = first_id;
    if (cdt.number_of_vertices() != static_cast<std::size_t>(id)) {
      out.problem = "two loop vertices coincide in the section";
      return false;
    }
    for (const auto& h : handles)
      for (std::size_t i = 0; i < h.size(); ++i) cdt.insert_constraint(h[i], h[(i + 1) % h.size()]);

    // Nesting depth of every face: a flood fill from the infinite face that stays within the
    // loops, then continues one level deeper across each loop edge met.
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
    std::vector<Cdt::Face_handle> stack;
    std::vector<Cdt::Edge> border;
    auto flood = [&](Cdt::Face_handle start, std::int32_t depth) {
      stack.push_back(start);
      while (!stack.empty()) {
        const Cdt::Face_handle f = stack.back();
        stack.pop_back();
        if (f->info() >= 0) continue;
        f->info() = depth;
        for (int i = 0; i < 3; ++i) {
          const Cdt::Face_handle n = f->neighbor(i);
          if (n->info() >= 0) continue;
          if (cdt.is_constrained(Cdt::Edge(f, i)))
            border.emplace_back(f, i);
          else
            stack.push_back(n);
        }
      }
    };
    flood(cdt.infinite_face(), 0);
    while (!border.empty()) {
      const Cdt::Edge e = border.back();
      border.pop_back();
      const Cdt::Face_handle n = e.first->neighbor(e.second);
      if (n->info() < 0) flood(n, e.first->info() + 1);
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
      if (f->info() % 2 == 1)
        out.triangles.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    // A loop's depth: the smaller of the depths on the two sides of its first edge.
    out.depth.assign(loops.size(), -1);
    for (std::size_t l = 0; l < loops.size(); ++l) {
      if (handles[l].size() < 2) continue;
      Cdt::Face_handle f;
      int i = 0;
      if (cdt.is_edge(handles[l][0], handles[l][1], f, i))
        out.depth[l] = std::min(f->info(), f->neighbor(i)->info());
    }
    return true;
  } catch (const std::exception& e) {
    out.triangles.clear();
    out.problem = std::string("loops cross or touch in the section (") + e.what() + ")";
    return false;
  }
}

}  // namespace

bool cdt_section(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                 SectionTriangulation& out) {
  if (loops.empty()) return true;
  // The conditioned points round differently from the given ones: should that make loops
  // that were apart touch, triangulate the section as given instead.
  if (triangulate(loops, true, out)) return true;
  out = SectionTriangulation{};
  return triangulate(loops, false, out);
}

}  // namespace conform::mesh::detail

#else

namespace conform::mesh::detail {

bool cdt_available() {
  return false;
}

bool cdt_section(const std::vector<std::vector<Eigen::Vector2d>>&, SectionTriangulation& out) {
  out.problem = "this build has no CGAL (libcgal-dev was not found at configure time)";
  return false;
}

}  // namespace conform::mesh::detail

#endif
