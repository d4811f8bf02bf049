#include "conform/membrane/slit_sheet.hpp"

#include "conform/mesh/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <stdexcept>
#include "range_error.hpp"

namespace conform::membrane {
namespace {

// Points from p0 (excluded) to p1 (included) with steps that start at `step` and grow by
// `ratio` up to `cap`; a last gap shorter than half a step is merged into the one before.
void march(std::vector<double>& out, double p0, double p1, double step, double ratio, double cap) {
  const double dir = p1 > p0 ? 1 : -1, length = std::abs(p1 - p0);
  double done = 0;
  while (length - done > 1.5 * step) {
    done += step;
    out.push_back(p0 + dir * done);
    step = std::min(step * ratio, cap);
  }
  out.push_back(p1);
}

// Positive half of an axis: fine (h_tip, growing by `tip_ratio` up to h) on both sides of the
// focus f (a tip, or 0), size h up to `fine`, then growing by `grading` up to `half`.
std::vector<double> half_axis(double focus, double h, double h_tip, double tip_ratio, double fine,
                              double half, double grading) {
  std::vector<double> inward{focus};
  if (focus > 0) march(inward, focus, 0, h_tip, tip_ratio, h);
  std::vector<double> axis(inward.rbegin(), inward.rend());
  if (focus == 0) axis = {0.0};
  std::vector<double> outward;
  march(outward, focus, fine, h_tip, tip_ratio, h);
  double last = outward.size() > 1 ? outward.back() - outward[outward.size() - 2] : h;
  march(outward, fine, half, std::min(last, h) * grading, grading, half);
  axis.insert(axis.end(), outward.begin(), outward.end());
  return axis;
}

std::vector<double> mirrored(const std::vector<double>& positive) {
  std::vector<double> axis;
  for (std::size_t i = positive.size(); i-- > 1;) axis.push_back(-positive[i]);
  axis.insert(axis.end(), positive.begin(), positive.end());
  return axis;
}

}  // namespace

void SlitSheetOptions::validate() const {
  const RangeCheck check("slit sheet");
  check(slit_length > 0 && std::isfinite(slit_length), "slit.length", slit_length, "> 0 m");
  check(width >= 8 * slit_length && std::isfinite(width), "sheet.width", width,
        ">= 8 x slit.length");
  check(element_size > 0 && element_size <= 0.25 * slit_length, "sheet.resolution", element_size,
        "(0, slit.length / 4] m");
  check(fine_zone >= 0 && std::isfinite(fine_zone), "fine_zone", fine_zone, ">= 0");
  check(grading >= 1 && grading <= 2, "grading", grading, "[1, 2]");
  check(tip_refinement >= 1 && tip_refinement <= 64, "tip_refinement", tip_refinement, "[1, 64]");
  check(tip_grading > 1 && tip_grading <= 2, "tip_grading", tip_grading, "(1, 2]");
  check(std::isfinite(slit_angle), "slit.angle", slit_angle, "finite");
  check(2 * width / element_size <= 2e4, "sheet.resolution", element_size, "too fine");
}

SlitSheet make_slit_sheet(const SlitSheetOptions& o) {
  o.validate();
  const double a = 0.5 * o.slit_length;
  const double h = o.element_size, h_tip = h / o.tip_refinement, half = 0.5 * o.width;
  const std::vector<double> us =
      mirrored(half_axis(a, h, h_tip, o.tip_grading, a * (1 + o.fine_zone), half, o.grading));
  const std::vector<double> vs =
      mirrored(half_axis(0, h, h_tip, o.tip_grading, a * o.fine_zone, half, o.grading));
  const auto nu = static_cast<std::int32_t>(us.size()), nv = static_cast<std::int32_t>(vs.size());
  SlitSheet sheet;
  sheet.slit_direction = Eigen::Vector3d(std::cos(o.slit_angle), std::sin(o.slit_angle), 0);
  sheet.slit_normal = Eigen::Vector3d(-std::sin(o.slit_angle), std::cos(o.slit_angle), 0);
  sheet.mesh = mesh::make_grid_sheet(us, vs, sheet.slit_direction, sheet.slit_normal, o.width);
  mesh::SkinnedMesh& m = sheet.mesh;
  const std::int32_t count = nu * nv;
  const auto id = [nu](std::int32_t i, std::int32_t j) { return j * nu + i; };
  sheet.border.assign(static_cast<std::size_t>(count), 0);
  for (std::int32_t j = 0; j < nv; ++j)
    for (std::int32_t i = 0; i < nu; ++i)
      sheet.border[std::size_t(id(i, j))] = i == 0 || j == 0 || i == nu - 1 || j == nv - 1;
  // The slit: on the grid line v = 0, interior vertices with |u| < a.
  const auto j0 = static_cast<std::int32_t>(std::find(vs.begin(), vs.end(), 0.0) - vs.begin());
  mesh::TopologyChange& c = sheet.slit;
  c.base_vertex_count = count;
  c.base_face_count = m.face_count();
  std::vector<std::int32_t> duplicate_of(static_cast<std::size_t>(count), -1);
  for (std::int32_t i = 0; i < nu; ++i) {
    const double u = us[std::size_t(i)];
    if (std::abs(u) >= a - 0.5 * h_tip) continue;
    const std::int32_t v = id(i, j0);
    duplicate_of[std::size_t(v)] = count + static_cast<std::int32_t>(c.new_vertices.size());
    c.new_vertices.push_back(mesh::NewVertex::duplicate(v));
    sheet.lip_upper.push_back(v);
    sheet.lip_lower.push_back(duplicate_of[std::size_t(v)]);
    sheet.lip_s.push_back(u);
  }
  // Faces below the slit (the row of quads j0 - 1) take the duplicates.
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const mesh::Face& face = m.faces[std::size_t(f)];
    bool below = true, touches = false;
    for (const std::int32_t v : face) {
      below = below && m.rest.col(v).dot(sheet.slit_normal) <= 1e-12 * o.width;
      touches = touches || duplicate_of[std::size_t(v)] >= 0;
    }
    if (!below || !touches) continue;
    mesh::Face moved = face;
    for (std::int32_t& v : moved)
      if (duplicate_of[std::size_t(v)] >= 0) v = duplicate_of[std::size_t(v)];
    c.removed_faces.push_back(f);
    c.added_faces.push_back(moved);
  }
  return sheet;
}

double normal_prestress(const SlitSheet& sheet, double sigma_xx, double sigma_yy) {
  const Eigen::Vector3d& n = sheet.slit_normal;
  return sigma_xx * n.x() * n.x() + sigma_yy * n.y() * n.y();
}

std::vector<double> slit_opening(const SlitSheet& sheet,
                                 const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  std::vector<double> w;
  w.reserve(sheet.lip_s.size());
  for (std::size_t i = 0; i < sheet.lip_s.size(); ++i)
    w.push_back((x.col(sheet.lip_upper[i]) - x.col(sheet.lip_lower[i])).dot(sheet.slit_normal));
  return w;
}

EllipseFit fit_ellipse(const std::vector<double>& s, const std::vector<double>& w, double a) {
  EllipseFit fit;
  double num = 0, den = 0, mean = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double shape = std::sqrt(std::max(0.0, 1 - (s[i] / a) * (s[i] / a)));
    num += shape * w[i];
    den += shape * shape;
    mean += w[i];
    fit.w_max = std::max(fit.w_max, w[i]);
  }
  if (s.empty() || den <= 0) return fit;
  fit.amplitude = num / den;
  mean /= double(s.size());
  double ss_res = 0, ss_tot = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double shape = std::sqrt(std::max(0.0, 1 - (s[i] / a) * (s[i] / a)));
    ss_res += (w[i] - fit.amplitude * shape) * (w[i] - fit.amplitude * shape);
    ss_tot += (w[i] - mean) * (w[i] - mean);
  }
  fit.r2 = ss_tot > 0 ? 1 - ss_res / ss_tot : 0;
  return fit;
}

}  // namespace conform::membrane
