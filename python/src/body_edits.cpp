// A body's topology changes from Python: cut, tear (a whole stroke, or one sample at a time)
// and drill, each refused with BufferError while zero-copy views are alive (body_arrays.cpp).
// Piece events of an edit reach the Python listeners once the edit is complete.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

#include "body.hpp"
#include "conform/mesh/cut_region.hpp"

namespace conform::python {
namespace {

const char* cut_status(mesh::CutStatus s) {
  return s == mesh::CutStatus::Cut ? "cut" : "missed";
}

py::dict cut(Body& b, const Eigen::Vector3d& point, const Eigen::Vector3d& normal, bool cap,
             const std::optional<Eigen::Vector3d>& seed) {
  b.check_no_views("cut");
  if (!point.allFinite() || !normal.allFinite() || normal.norm() == 0)
    throw std::invalid_argument("cut: the point must be finite and the normal finite and non-zero");
  mesh::CutOptions o;
  o.cap = cap;
  if (seed) o.region = mesh::CutRegion::seed(*seed);
  const auto before = b.get().piece_count();
  const mesh::CutResult r = b.get().cut(cga::Plane<double>::from_normal_point(normal, point), o);
  b.deliver_events();
  py::dict d;
  d["status"] = cut_status(r.status);
  d["crossed_edges"] = r.crossed_edges;
  d["loops"] = r.loops;
  d["capped_loops"] = r.capped_loops;
  d["cap_faces"] = r.cap_faces;
  d["new_pieces"] = b.get().piece_count() - before;
  d["message"] = r.message;
  return d;
}

py::dict drill(Body& b, const Eigen::Vector3d& tip, const Eigen::Vector3d& base, double radius,
               bool tube) {
  b.check_no_views("drill");
  mesh::DrillOptions o;
  o.tube = tube;
  const mesh::DrillResult r = b.get().drill({tip, base, radius}, o);
  b.deliver_events();
  py::dict d;
  d["holes"] = r.holes;
  d["rim_vertices"] = r.rim_vertices;
  d["removed_area"] = r.removed_area;
  d["tubes"] = r.tubes;
  d["tube_faces"] = r.tube_faces;
  d["changes"] = r.changes.size();
  d["message"] = r.message;
  return d;
}

void begin_tear(Body& b, bool smooth_lips) {
  mesh::TearOptions o;
  o.smooth_lips = smooth_lips;
  b.get().begin_tear(o);
}

bool tear_advance(Body& b, const Eigen::Vector3d& a, const Eigen::Vector3d& blade_b, double t) {
  b.check_no_views("tear_advance");
  const mesh::TearStep s = b.get().tear_advance({t, a, blade_b});
  b.deliver_events();
  return s.extended;
}

// A whole stroke: sample i's blade runs from a[i] to b[i] at time times[i] (default i).
int tear(Body& b, const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& blade_b,
         const std::optional<std::vector<double>>& times, bool smooth_lips) {
  if (a.rows() != blade_b.rows() || (times && times->size() != std::size_t(a.rows())))
    throw std::invalid_argument("tear: blade_a, blade_b (and times) must have as many rows");
  b.check_no_views("tear");
  begin_tear(b, smooth_lips);
  int extended = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const double t = times ? (*times)[std::size_t(i)] : double(i);
    extended +=
        b.get().tear_advance({t, a.row(i).transpose(), blade_b.row(i).transpose()}).extended;
  }
  b.deliver_events();
  return extended;
}

}  // namespace

void bind_body_edits(py::class_<Body>& c) {
  c.def("cut", &cut, py::arg("point"), py::arg("normal"), py::arg("cap") = false,
        py::arg("seed") = py::none(),
        "Cuts along the plane through `point` with `normal` (only its section nearest `seed` "
        "when given; capped when cap). Returns {status: 'cut'|'missed', ...}.")
      .def("drill", &drill, py::arg("tip"), py::arg("base"), py::arg("radius"),
           py::arg("tube") = false,
           "Drills a cylinder from base to tip; tube joins entry and exit holes. Returns "
           "{holes, removed_area, ...}.")
      .def("begin_tear", &begin_tear, py::arg("smooth_lips") = false,
           "Starts a tear (advance it with tear_advance).")
      .def("tear_advance", &tear_advance, py::arg("a"), py::arg("b"), py::arg("t") = 0.0,
           "One scalpel sample: the blade from a to b at time t. True when the tear grew.")
      .def("tear", &tear, py::arg("blade_a"), py::arg("blade_b"), py::arg("times") = py::none(),
           py::arg("smooth_lips") = false,
           "A new tear along a whole stroke ((N, 3) blade ends); the samples that extended it.")
      .def_property_readonly("tear_message", [](const Body& b) {
        return b.get().tear() ? b.get().tear()->message() : std::string();
      });
}

}  // namespace conform::python
