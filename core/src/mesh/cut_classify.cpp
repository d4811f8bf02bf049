#include "cut_classify.hpp"

#include <cmath>
#include <stdexcept>

#include "conform/cga/point.hpp"

namespace conform::mesh::cutting {

cga::Plane<double> unit_plane(const cga::Plane<double>& plane) {
  const Eigen::Vector3d n = plane.normal();
  const double len = n.norm();
  if (!std::isfinite(len) || !std::isfinite(plane.distance()) || !(len > 0))
    throw std::invalid_argument(
        "cut: the plane must have a finite, non-zero normal and a finite distance");
  return cga::Plane<double>::from_normal_distance(n / len, plane.distance() / len);
}

Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

void CutClassification::check_input() const {
  if (!(options_.snap_fraction >= 0 && options_.snap_fraction < 0.5) ||
      !(options_.plane_tolerance >= 0) || !(options_.min_angle >= 0 && options_.min_angle < 0.5))
    throw std::invalid_argument(
        "cut: snap_fraction must be in [0, 0.5), plane_tolerance ≥ 0 and min_angle in [0, "
        "0.5)");
  if (mesh_.current.cols() != nv0_)
    throw std::invalid_argument("cut: the current positions must be finite, one per vertex");
  if (const std::string problem = options_.region.validate(); !problem.empty())
    throw std::invalid_argument(problem);
}

void CutClassification::measure_distances() {
  std::vector<double>& dist = sc_.dist;
  dist.resize(static_cast<std::size_t>(nv0_));
  if (nv0_ == 0) return;
  const std::int32_t nv0 = nv0_;
  const double* x = mesh_.current.data();
  double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
  double reach_pos = 0, reach_neg = 0;
  bool finite = true;
  auto pass = [&](auto distance) {
    for (std::int32_t i = 0; i < nv0; ++i, x += 3) {
      for (int k = 0; k < 3; ++k) {
        finite &= std::isfinite(x[k]);
        lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
      }
      const double s = distance(x);
      dist[static_cast<std::size_t>(i)] = s;
      reach_pos = std::max(reach_pos, s), reach_neg = std::max(reach_neg, -s);
    }
  };
  const cga::Plane<double>& plane = plane_;
  if (predicates_ == Predicates::Cga) {
    pass([&](const double* p) {
      return dot(cga::Point<double>::up(Eigen::Vector3d(p[0], p[1], p[2])), plane);
    });
  } else {
    const Eigen::Vector3d n = plane.normal();
    const double d = plane.distance();
    pass([&](const double* p) { return n.x() * p[0] + n.y() * p[1] + n.z() * p[2] - d; });
  }
  if (!finite)
    throw std::invalid_argument("cut: the current positions must be finite, one per vertex");
  diagonal_ = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  reach_pos_ = reach_pos, reach_neg_ = reach_neg;
}

void CutClassification::classify_sides() {
  const double eps = eps_;
  const double k_snap = snap_ / (1 - snap_) * (1 + 1e-9);  // a margin for rounding
  const double near_pos = k_snap * reach_neg_, near_neg = k_snap * reach_pos_;
  const std::vector<double>& dist = sc_.dist;
  std::vector<std::int8_t>& side = sc_.side;
  std::vector<std::uint8_t>& code = sc_.code;
  side.resize(static_cast<std::size_t>(nv0_));
  code.resize(static_cast<std::size_t>(nv0_));
  for (std::int32_t i = 0; i < nv0_; ++i) {
    const double s = dist[static_cast<std::size_t>(i)];
    const std::int8_t si = s > eps ? 1 : (s < -eps ? -1 : 0);
    side[static_cast<std::size_t>(i)] = si;
    code[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>((si == 0  ? 1
                                   : si > 0 ? 2
                                            : 8) |
                                  ((si > 0 && s < near_pos) || (si < 0 && -s < near_neg) ? 16 : 0));
  }
}

void CutClassification::find_work_faces() {
  const auto nf = static_cast<std::size_t>(nf0_);
  const Face* const faces = mesh_.faces.data();
  const std::uint8_t* const cd = sc_.code.data();
  std::vector<std::int32_t>& work = sc_.work;
  work.clear();
  work.reserve(256);
  int any = 0;
  const auto bound = static_cast<std::uint32_t>(nv0_);
  for (std::size_t fi = 0; fi < nf; ++fi) {
    const Face& f = faces[fi];
    const auto a = static_cast<std::uint32_t>(f[0]), b = static_cast<std::uint32_t>(f[1]),
               c = static_cast<std::uint32_t>(f[2]);
    if ((a >= bound) | (b >= bound) | (c >= bound))
      throw std::invalid_argument("cut: face index out of range");
    const int fc = cd[a] | cd[b] | cd[c];
    if (fc == 2 || fc == 8) {  // strictly on one side, no vertex near the plane
      any |= fc;
      continue;
    }
    work.push_back(static_cast<std::int32_t>(fi));
  }
  face_pos_ = (any & 2) != 0, face_neg_ = (any & 8) != 0;
}

}  // namespace conform::mesh::cutting
