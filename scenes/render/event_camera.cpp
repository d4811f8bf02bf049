#include "render/event_camera.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace conform::scenes {

namespace {

struct Points {
  Eigen::Matrix3Xd x;      // the event's points (or every vertex)
  Eigen::Vector3d normal;  // their mean outward normal
  bool event = false;
};

Points gather(std::span<const FrameSnapshot> panels) {
  Eigen::Index n = 0;
  for (const auto& p : panels) n += static_cast<Eigen::Index>(p.focus.size());
  Points pts;
  pts.event = n > 0;
  if (!pts.event)
    for (const auto& p : panels) n += p.positions.cols();
  pts.x.resize(3, n);
  pts.normal.setZero();
  Eigen::Index k = 0;
  for (const auto& p : panels) {
    if (pts.event) {
      for (const auto v : p.focus) {
        pts.x.col(k++) = p.positions.col(v);
        pts.normal += p.normals.col(v);
      }
    } else {
      pts.x.middleCols(k, p.positions.cols()) = p.positions;
      k += p.positions.cols();
    }
  }
  return pts;
}

}  // namespace

Camera aim_camera(std::span<const FrameSnapshot> panels, const RenderCamera& s, double aspect) {
  Camera c;
  c.view_angle = s.view_angle;
  c.how = "event";
  const Points pts = gather(panels);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();
  double extent = 1;
  if (pts.x.cols() > 0) {
    centre = pts.x.rowwise().mean();
    const Eigen::Matrix3Xd d = pts.x.colwise() - centre;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(d * d.transpose());
    axis = eig.eigenvectors().col(2);  // the long axis of the wound
    extent = 2 * d.colwise().norm().maxCoeff();
  }
  extent = std::max(extent, 1e-3);
  Eigen::Vector3d view = pts.normal;  // from the target towards the camera
  if (!pts.event) {
    c.how = "mesh";
    view = Eigen::Vector3d(1, 0.4, 0.8);
  }
  if (view.norm() < 1e-9) view = Eigen::Vector3d::UnitX();
  view.normalize();
  c.target = s.has_target ? s.target : centre;
  const double half = std::tan(0.5 * c.view_angle * std::numbers::pi / 180);
  // The wound lies across the picture (its width is `aspect` times its height).
  const double distance = s.framing * extent / (2 * half * aspect);
  c.position = s.has_position ? s.position : Eigen::Vector3d(c.target + distance * view);
  Eigen::Vector3d up = view.cross(axis);
  if (up.norm() < 1e-6) up = view.unitOrthogonal();
  up.normalize();
  if (up.y() < 0) up = -up;  // of the two, the one nearer the world's up
  c.up = s.has_up ? s.up.normalized() : up;
  if (s.has_target || s.has_position || s.has_up) c.how = "scene";
  return c;
}

double strip_view_angle(double panel_view_angle, double aspect, double max_parallax_deg) {
  // One panel's width at the target, d away: 2 d tan(a/2) aspect. From s times as far, with
  // tan(a'/2) = tan(a/2) / s, the target's framing is the same, and the next panel, a width
  // away, is seen at atan(width / (s d)) from the first: at most max_parallax_deg.
  const double deg = std::numbers::pi / 180;
  const double half = std::tan(0.5 * panel_view_angle * deg);
  const double s = std::max(1.0, 2 * half * aspect / std::tan(max_parallax_deg * deg));
  return 2 * std::atan(half / s) / deg;
}

ViewFrame view_frame(const Camera& c) {
  Eigen::Vector3d back = c.position - c.target;
  const double d = std::max(back.norm(), 1e-12);
  back /= d;
  Eigen::Vector3d right = (-back).cross(c.up);
  if (right.norm() < 1e-9) right = back.unitOrthogonal();
  right.normalize();
  ViewFrame f{Eigen::Matrix3d::Identity(), c.position, 1 / d};
  f.rotation.row(0) = right;
  f.rotation.row(1) = back.cross(right);
  f.rotation.row(2) = back;
  return f;
}

StripCamera strip_camera(const Camera& panel, double aspect, double max_parallax_deg) {
  const double deg = std::numbers::pi / 180;
  const ViewFrame view = view_frame(panel);
  const Eigen::Vector3d right = view.rotation.row(0), back = view.rotation.row(2);
  const double d = 1 / view.scale;
  const double angle = strip_view_angle(panel.view_angle, aspect, max_parallax_deg);
  const double half = std::tan(0.5 * panel.view_angle * deg);
  const double s = half / std::tan(0.5 * angle * deg);  // how many times as far
  StripCamera strip{panel, 2 * d * half * aspect * right};
  strip.camera.position = panel.target + s * d * back;
  strip.camera.view_angle = angle;
  strip.camera.up = view.rotation.row(1);  // the panel's up, made square to the view
  return strip;
}

Camera view_frame_camera(double view_angle) {
  return {Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), view_angle,
          "view frame"};
}

}  // namespace conform::scenes
