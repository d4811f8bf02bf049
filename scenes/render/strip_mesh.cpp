#include "render/strip_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>

namespace conform::scenes {

namespace {

struct Corner {
  Eigen::Vector3d x;
  Rgb c;
};
using Polygon = std::vector<Corner>;

// A half-space n·x + d >= 0.
struct HalfSpace {
  Eigen::Vector3d n;
  double d;
  double operator()(const Eigen::Vector3d& x) const { return n.dot(x) + d; }
};

// Sutherland-Hodgman: the part of a convex polygon inside h, colours interpolated.
Polygon clip(const Polygon& in, const HalfSpace& h) {
  Polygon out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Corner &a = in[i], &b = in[(i + 1) % in.size()];
    const double ga = h(a.x), gb = h(b.x);
    if (ga >= 0) out.push_back(a);
    if ((ga >= 0) != (gb >= 0)) {
      const double t = ga / (ga - gb);
      Corner m{a.x + t * (b.x - a.x), {}};
      for (int k = 0; k < 3; ++k) m.c[k] = a.c[k] + t * (b.c[k] - a.c[k]);
      out.push_back(m);
    }
  }
  return out;
}

// Panel k's column of the strip's picture: the points whose horizontal image coordinate, in
// [-1, 1] across the whole picture, lies in [-1 + 2k/n, -1 + 2(k+1)/n]. With the camera's eye
// e, view f, right r and horizontal half-angle h, that coordinate is r·(p-e) / (f·(p-e) tan h):
// two planes through the eye.
std::array<HalfSpace, 2> column(const StripCamera& s, int k, int n, double aspect) {
  const Camera& c = s.camera;
  const Eigen::Vector3d e = c.position, f = (c.target - e).normalized(),
                        r = f.cross(c.up).normalized();
  const double tan_h = std::tan(0.5 * c.view_angle * std::numbers::pi / 180) * aspect * n;
  const double x0 = -1 + 2.0 * k / n, x1 = x0 + 2.0 / n;
  const Eigen::Vector3d left = r - x0 * tan_h * f, right = x1 * tan_h * f - r;
  return {HalfSpace{left, -left.dot(e)}, HalfSpace{right, -right.dot(e)}};
}

// A skin's thickness for the inner layer: half a percent of the surface's size (3 mm on the
// arm), thin enough not to show from outside, thick enough not to fight the outer layer for
// depth.
double bed_depth(const FrameSnapshot& s) {
  if (s.positions.cols() == 0) return 0;
  const Eigen::Vector3d lo = s.positions.rowwise().minCoeff(),
                        hi = s.positions.rowwise().maxCoeff();
  return 0.005 * (hi - lo).norm();
}

std::uint8_t byte(double c) {
  return static_cast<std::uint8_t>(std::lround(255 * std::clamp(c, 0.0, 1.0)));
}

// Every panel's triangles, clipped, as a triangle soup.
std::vector<Corner> strip_triangles(const std::vector<FrameSnapshot>& frame,
                                    const ColourScale& scale, const StripCamera& strip,
                                    double aspect) {
  std::vector<Corner> soup;
  const int n = static_cast<int>(frame.size());
  for (int k = 0; k < n; ++k) {
    const FrameSnapshot& s = frame[std::size_t(k)];
    const Eigen::Vector3d shift = strip.offset(k, n);
    const auto walls = column(strip, k, n, aspect);
    const double depth = bed_depth(s);
    const auto add = [&](const Polygon& tri) {
      const Polygon p = clip(clip(tri, walls[0]), walls[1]);
      for (std::size_t i = 2; i < p.size(); ++i) soup.insert(soup.end(), {p[0], p[i - 1], p[i]});
    };
    for (const auto& f : s.faces) {
      Polygon outer, bed;
      for (const auto v : f) {
        const Eigen::Vector3d x = s.positions.col(v) + shift;
        outer.push_back({x, scale(s.scalar[std::size_t(v)])});
        bed.push_back({x - depth * s.normals.col(v), kWoundBed});
      }
      add(outer);
      std::swap(bed[1], bed[2]);  // the bed faces inwards
      add(bed);
    }
  }
  return soup;
}

}  // namespace

std::string strip_ply(const std::vector<FrameSnapshot>& frame, const ColourScale& scale,
                      const StripCamera& strip, double aspect) {
  const std::vector<Corner> soup = strip_triangles(frame, scale, strip, aspect);
  const ViewFrame view = view_frame(strip.camera);
  std::ostringstream out(std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << soup.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nelement face "
      << soup.size() / 3 << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Corner& k : soup) {
    const Eigen::Vector3d x = view(k.x);
    const float f[3] = {float(x.x()), float(x.y()), float(x.z())};
    const std::uint8_t rgb[3] = {byte(k.c[0]), byte(k.c[1]), byte(k.c[2])};
    out.write(reinterpret_cast<const char*>(f), sizeof f);
    out.write(reinterpret_cast<const char*>(rgb), sizeof rgb);
  }
  for (std::int32_t i = 0; i + 2 < std::int32_t(soup.size()); i += 3) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {i, i + 1, i + 2};
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(idx), sizeof idx);
  }
  return std::move(out).str();
}

}  // namespace conform::scenes
