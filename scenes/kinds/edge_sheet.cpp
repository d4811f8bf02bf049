#include "kinds/edge_sheet.hpp"

#include "conform/mesh/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace conform::scenes {
namespace {

// One axis through 0, symmetric: steps of h up to `fine`, then growing by `grading` up to
// `half`; a last gap under half a step is merged into the one before.
std::vector<double> graded_axis(double half, double h, double fine, double grading) {
  std::vector<double> positive{0.0};
  double x = 0, step = h;
  while (half - x > 1.5 * step) {
    x += step;
    positive.push_back(x);
    if (x >= fine - 1e-9 * h) step *= grading;
  }
  positive.push_back(half);
  std::vector<double> axis;
  for (std::size_t i = positive.size(); i-- > 1;) axis.push_back(-positive[i]);
  axis.insert(axis.end(), positive.begin(), positive.end());
  return axis;
}

}  // namespace

EdgeSheet make_edge_sheet(const EdgeSheetOptions& o) {
  if (!(o.width > 0 && o.element_size > 0 && o.element_size <= 0.05 * o.width))
    throw std::invalid_argument("edge sheet: sheet.resolution must be in (0, width / 20]");
  if (!(o.grading >= 1 && o.grading <= 2))
    throw std::invalid_argument("edge sheet: grading must be in [1, 2]");
  const double half = 0.5 * o.width;
  EdgeSheet sheet;
  sheet.xs = graded_axis(half, o.element_size, std::min(o.fine_across, half), o.grading);
  sheet.ys = graded_axis(half, o.element_size, std::min(o.fine_along, half), o.grading);
  sheet.mesh = mesh::make_grid_sheet(sheet.xs, sheet.ys, Eigen::Vector3d::UnitX(),
                                     Eigen::Vector3d::UnitY(), o.width);
  const auto nx = std::int32_t(sheet.xs.size()), ny = std::int32_t(sheet.ys.size());
  for (std::int32_t j = 0; j < ny; ++j)
    if (sheet.ys[std::size_t(j)] == 0)
      for (std::int32_t i = 0; i < nx; ++i) sheet.mid_row.push_back(j * nx + i);
  return sheet;
}

}  // namespace conform::scenes
