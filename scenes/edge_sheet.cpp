#include "edge_sheet.hpp"

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
  const auto nx = std::int32_t(sheet.xs.size()), ny = std::int32_t(sheet.ys.size());
  const std::int32_t count = nx * ny;
  mesh::SkinnedMesh& m = sheet.mesh;
  m.rest.resize(3, count);
  m.bones.setZero(mesh::kMaxInfluences, count);
  m.weights.setZero(mesh::kMaxInfluences, count);
  m.uvs.resize(2, count);
  m.normals.resize(3, count);
  const auto id = [nx](std::int32_t i, std::int32_t j) { return j * nx + i; };
  for (std::int32_t j = 0; j < ny; ++j)
    for (std::int32_t i = 0; i < nx; ++i) {
      const std::int32_t k = id(i, j);
      const double x = sheet.xs[std::size_t(i)], y = sheet.ys[std::size_t(j)];
      m.rest.col(k) = Eigen::Vector3d(x, y, 0);
      m.weights(0, k) = 1;
      m.uvs.col(k) = Eigen::Vector2d(x / o.width + 0.5, y / o.width + 0.5);
      m.normals.col(k) = Eigen::Vector3d::UnitZ();
      if (y == 0) sheet.mid_row.push_back(k);
    }
  m.current = m.rest;
  // Quads split along alternating diagonals, counter-clockwise about +z.
  for (std::int32_t j = 0; j + 1 < ny; ++j)
    for (std::int32_t i = 0; i + 1 < nx; ++i) {
      const std::int32_t p00 = id(i, j), p10 = id(i + 1, j), p01 = id(i, j + 1),
                         p11 = id(i + 1, j + 1);
      if ((i + j) % 2 == 0) {
        m.faces.push_back({p00, p10, p11});
        m.faces.push_back({p00, p11, p01});
      } else {
        m.faces.push_back({p00, p10, p01});
        m.faces.push_back({p10, p11, p01});
      }
    }
  return sheet;
}

}  // namespace conform::scenes
