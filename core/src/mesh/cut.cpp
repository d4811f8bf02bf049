#include "conform/mesh/cut.hpp"

#include <cmath>
#include <stdexcept>

#include "conform/cga/point.hpp"
#include "cut_computation.hpp"

namespace conform::mesh {

using detail::Predicates;

namespace detail {

void classify_vertices(const SkinnedMesh& mesh, const cga::Plane<double>& plane_in,
                       Predicates predicates, std::vector<double>& distance) {
  const cga::Plane<double> plane = cutting::unit_plane(plane_in);
  const Eigen::Index nv = mesh.current.cols();
  distance.resize(static_cast<std::size_t>(nv));
  if (predicates == Predicates::Cga) {
    // X·Π with X = up(x): x·n − d (the ½x² e∞ and e0 parts meet Π's e∞ and zero e0).
    for (Eigen::Index i = 0; i < nv; ++i)
      distance[static_cast<std::size_t>(i)] =
          dot(cga::Point<double>::up(Eigen::Vector3d(mesh.current.col(i))), plane);
  } else {
    const Eigen::Vector3d n = plane.normal();
    const double d = plane.distance();
    for (Eigen::Index i = 0; i < nv; ++i)
      distance[static_cast<std::size_t>(i)] = n.dot(mesh.current.col(i)) - d;
  }
}

}  // namespace detail

namespace cutting {

CutResult CutComputation::run() {
  check_input();
  measure_distances();
  result_.change.base_vertex_count = nv0_;
  result_.change.edit = EditKind::cut;
  result_.change.base_face_count = nf0_;
  if (nf0_ == 0) return std::move(result_);
  eps_ = options_.plane_tolerance * diagonal_;
  if (!(reach_pos_ > eps_) || !(reach_neg_ > eps_)) {
    // Every vertex on one side or on the plane: only faces lying in the plane could
    // separate, and they go to the side of the material (opposite their normal), i.e. the
    // same side.
    result_.message = "the plane does not cross the mesh";
    return std::move(result_);
  }
  classify_sides();
  find_work_faces();
  snap();
  if (outside_work_) add_faces_around_far_snaps();
  if (options_.region.shape != CutRegion::Shape::everywhere && !select_sections()) {
    result_.message = "the plane crosses the mesh only in sections outside the region";
    return std::move(result_);
  }
  if (!split_crossed_faces()) {
    result_.change.new_vertices.clear();
    result_.crossed_edges = 0;
    result_.message = "the plane only touches the mesh";
    return std::move(result_);
  }
  separate_fans();
  separate_crossings();
  emit_faces();
  result_.status = CutStatus::Cut;
  if (options_.cap) cap();
  return std::move(result_);
}

}  // namespace cutting

CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options) {
  return detail::compute_cut(mesh, plane, options, Predicates::Cga);
}

CutOutcome cut(SkinnedMesh& mesh, Adjacency& adjacency, const cga::Plane<double>& plane,
               const CutOptions& options) {
  CutOutcome out;
  out.result = compute_cut(mesh, plane, options);
  if (out.result.status == CutStatus::Cut) apply(mesh, out.result.change, &adjacency);
  out.pieces = label_pieces(mesh);
  return out;
}

}  // namespace conform::mesh
