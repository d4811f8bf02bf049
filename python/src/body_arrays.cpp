// A body's data as numpy arrays.
//
// Views (no copy, read-only, their base object keeps the body and its world alive):
//   positions       (V, 3) float64  the mesh's current positions; reading the property first
//                                    copies the simulated positions into the mesh (sync), so a
//                                    view kept across step() shows the positions of its last
//                                    sync until the property is read again (which refreshes
//                                    every live view in place)
//   rest_positions  (V, 3) float64  bind-pose positions
//   faces           (F, 3) int32    triangles (counter-clockwise)
//   bone_ids        (V, 4) int32    the 4 largest influences' bones
//   bone_weights    (V, 4) float64  their weights
// An edit (cut, tear, drill) can grow and move that storage, so an edit refuses to run while
// any such view (or an array derived from one) is alive: it raises BufferError, as Python's
// own bytearray does when resized under a memoryview. A view therefore never dangles.
// Copies (new arrays, valid forever): velocities, targets, normals, masses, kinematic,
// detached, piece_slots, face_kinds, face_ops and the tear's borders, tips and openings.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "body.hpp"

namespace conform::python {
namespace {

/// The base object of the zero-copy views: counts them on the body, keeps it alive.
struct ViewBase {
  py::object body;
  std::shared_ptr<int> count;
  ViewBase(py::object b, std::shared_ptr<int> c) : body(std::move(b)), count(std::move(c)) {
    ++*count;
  }
  ~ViewBase() { --*count; }
  ViewBase(const ViewBase&) = delete;
  ViewBase& operator=(const ViewBase&) = delete;
};

template <class T>
py::array view(const py::object& self, const T* data, py::ssize_t rows, py::ssize_t cols) {
  const Body& b = self.cast<const Body&>();
  py::object base = py::cast(new ViewBase(self, b.views), py::return_value_policy::take_ownership);
  py::array_t<T> a({rows, cols}, {cols * py::ssize_t(sizeof(T)), py::ssize_t(sizeof(T))}, data,
                   base);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// A (V, 3) copy of a per-vertex vector query.
template <class F>
py::array_t<double> per_vertex3(const Body& b, F&& f) {
  const std::int32_t n = b.get().vertex_count();
  py::array_t<double> out({py::ssize_t(n), py::ssize_t(3)});
  auto r = out.template mutable_unchecked<2>();
  for (std::int32_t v = 0; v < n; ++v) {
    const Eigen::Vector3d x = f(v);
    for (int k = 0; k < 3; ++k) r(v, k) = x[k];
  }
  return out;
}

template <class T, class F>
py::array_t<T> per_vertex(const Body& b, F&& f) {
  const std::int32_t n = b.get().vertex_count();
  py::array_t<T> out(n);
  auto r = out.template mutable_unchecked<1>();
  for (std::int32_t v = 0; v < n; ++v) r(v) = f(v);
  return out;
}

template <class T>
py::array_t<T> copy(const std::vector<T>& v) {
  return py::array_t<T>(py::ssize_t(v.size()), v.data());
}

void bind_views(py::class_<Body>& c) {
  c.def_property_readonly(
       "positions",
       [](py::object self) {
         Body& b = self.cast<Body&>();
         b.get().sync_mesh();
         const auto& x = b.get().mesh().current;
         return view(self, x.data(), x.cols(), 3);
       },
       "(V, 3) view of the simulated positions (synced on each read).")
      .def_property_readonly(
          "rest_positions",
          [](py::object self) {
            const auto& x = self.cast<const Body&>().get().mesh().rest;
            return view(self, x.data(), x.cols(), 3);
          },
          "(V, 3) view of the bind-pose positions.")
      .def_property_readonly(
          "faces",
          [](py::object self) {
            const auto& f = self.cast<const Body&>().get().mesh().faces;
            return view(self, f.empty() ? nullptr : f.data()->data(), py::ssize_t(f.size()), 3);
          },
          "(F, 3) view of the triangles.")
      .def_property_readonly(
          "bone_ids",
          [](py::object self) {
            const auto& x = self.cast<const Body&>().get().mesh().bones;
            return view(self, x.data(), x.cols(), 4);
          },
          "(V, 4) view of the influences' bones.")
      .def_property_readonly(
          "bone_weights",
          [](py::object self) {
            const auto& x = self.cast<const Body&>().get().mesh().weights;
            return view(self, x.data(), x.cols(), 4);
          },
          "(V, 4) view of the influences' weights.")
      .def_property_readonly(
          "live_views", [](const Body& b) { return *b.views; },
          "How many zero-copy views of this body are alive.");
}

void bind_vertex_copies(py::class_<Body>& c) {
  using B = const Body&;
  c.def_property_readonly(
       "velocities",
       [](B b) { return per_vertex3(b, [&](std::int32_t v) { return b.get().velocity(v); }); },
       "(V, 3) copy, m/s.")
      .def_property_readonly(
          "targets",
          [](B b) { return per_vertex3(b, [&](std::int32_t v) { return b.get().target(v); }); },
          "(V, 3) copy: the skinned targets of the last substep.")
      .def_property_readonly(
          "normals",
          [](B b) {
            const Eigen::Matrix3Xd n = b.get().normals();
            return per_vertex3(b, [&](std::int32_t v) { return Eigen::Vector3d(n.col(v)); });
          },
          "(V, 3) copy: area-weighted vertex normals at the simulated positions.")
      .def_property_readonly(
          "masses",
          [](B b) {
            return per_vertex<double>(b, [&](std::int32_t v) { return b.get().mass(v); });
          },
          "(V,) copy, kg.")
      .def_property_readonly(
          "kinematic",
          [](B b) {
            return per_vertex<bool>(b, [&](std::int32_t v) { return b.get().kinematic(v); });
          },
          "(V,) copy.")
      .def_property_readonly(
          "detached",
          [](B b) {
            return per_vertex<bool>(b, [&](std::int32_t v) { return b.get().detached(v); });
          },
          "(V,) copy: vertices that left Bullet (the inside of a drilled hole).")
      .def_property_readonly(
          "piece_slots",
          [](B b) {
            return per_vertex<std::int32_t>(
                b, [&](std::int32_t v) { return b.get().piece_of(v).index; });
          },
          "(V,) copy: the slot of each vertex's piece (-1: detached).");
}

void bind_face_copies(py::class_<Body>& c) {
  using B = const Body&;
  c.def_property_readonly(
       "face_kinds",
       [](B b) {
         const auto& m = b.get().mesh();
         std::vector<std::uint8_t> k(static_cast<std::size_t>(m.face_count()));
         for (std::int32_t f = 0; f < m.face_count(); ++f) k[f] = std::uint8_t(m.face_tag(f).kind);
         return copy(k);
       },
       "(F,) copy: 0 skin, 1 cap, 2 tube wall.")
      .def_property_readonly(
          "face_ops",
          [](B b) {
            const auto& m = b.get().mesh();
            std::vector<std::uint32_t> k(static_cast<std::size_t>(m.face_count()));
            for (std::int32_t f = 0; f < m.face_count(); ++f) k[f] = m.face_tag(f).op;
            return copy(k);
          },
          "(F,) copy: the edit that made each face (0: the model).");
}

// The tear's borders, tips and the width between the borders' copies of each path point.
void bind_tear(py::class_<Body>& c) {
  using B = const Body&;
  c.def_property_readonly(
       "tear_borders",
       [](B b) -> py::object {
         const mesh::Tear* t = b.get().tear();
         if (!t || !t->started()) return py::none();
         return py::make_tuple(copy(t->left_border()), copy(t->right_border()));
       },
       "(left, right) vertex chains from the start to the tip (copies), or None.")
      .def_property_readonly(
          "tear_tips",
          [](B b) -> py::object {
            const mesh::Tear* t = b.get().tear();
            if (!t || !t->started()) return py::none();
            const auto left = t->left_border();
            return copy(std::vector<std::int32_t>{left.front(), left.back()});
          },
          "[start, tip] vertices of the tear (copy), or None.")
      .def_property_readonly(
          "tear_openings",
          [](B b) -> py::object {
            const mesh::Tear* t = b.get().tear();
            if (!t || !t->started()) return py::none();
            const auto l = t->left_border(), r = t->right_border();
            std::vector<double> w(std::min(l.size(), r.size()));
            for (std::size_t i = 0; i < w.size(); ++i)
              w[i] = (b.get().position(l[i]) - b.get().position(r[i])).norm();
            return copy(w);
          },
          "Distance between the borders' copies of each path point, m (copy), or None.")
      .def_property_readonly(
          "tear_length",
          [](B b) {
            const mesh::Tear* t = b.get().tear();
            return t && t->started() ? t->length() : 0.0;
          },
          "m");
}

}  // namespace

void bind_body_arrays(py::class_<Body>& c) {
  py::class_<ViewBase>(c, "_ViewBase", "The base object of a body's zero-copy array views.");
  bind_views(c);
  bind_vertex_copies(c);
  bind_face_copies(c);
  bind_tear(c);
}

}  // namespace conform::python
