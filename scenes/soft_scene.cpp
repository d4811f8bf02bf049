#include "soft_scene.hpp"

#include <cmath>

#include "conform/bullet/convert.hpp"

namespace conform::scenes {

SoftWorld::SoftWorld(const CommonSettings& c)
    : bullet::SoftWorld(bullet::to_bt(c.gravity)), dt(c.dt / c.substeps), substeps(c.substeps) {
  world.getSolverInfo().m_numIterations = c.solver_iterations;
  plugin = std::make_unique<bullet::Plugin>(world);
}

bullet::Material read_material(Reader& root, const bullet::Material& d) {
  Reader r = root.object("material");
  bullet::Material m;
  m.link_stiffness = r.number("link_stiffness", d.link_stiffness, 1e-4, 1);
  m.damping = r.number("damping", d.damping, 0, 0.999);
  m.pretension = r.number("pretension", d.pretension, 0, 0.9);
  m.density = r.number("density", d.density, 1e-4, 1e4);
  m.target_stiffness = r.number("target_stiffness", d.target_stiffness, 0, 1e7);
  m.target_damping = r.number("target_damping", d.target_damping, 0, 1e5);
  m.kinematic_weight = r.number("kinematic_weight", d.kinematic_weight, 0, 2);
  m.position_iterations = r.integer("position_iterations", d.position_iterations, 1, 200);
  m.margin = r.number("margin", d.margin, 0, 1);
  r.finish();
  return m;
}

mesh::ScalpelSample Stroke::sample(int i) const {
  const double u = samples > 1 ? double(i) / (samples - 1) : 0.0;
  const Eigen::Vector3d p = (1 - u) * from + u * to;
  return {time(i), p + blade_a, p + blade_b};
}

Stroke read_stroke(Reader& r, const Stroke& d) {
  Stroke s;
  s.at = r.number("at", d.at, 0, 1e5);
  s.duration = r.number("duration", d.duration, 0, 1e5);
  s.samples = r.integer("samples", d.samples, 2, 100000);
  s.from = r.vec3("from", d.from);
  s.to = r.vec3("to", d.to);
  s.blade_a = r.vec3("blade_a", d.blade_a);
  s.blade_b = r.vec3("blade_b", d.blade_b);
  if ((s.blade_a - s.blade_b).norm() < 1e-6)
    r.fail("blade_b", r.has("blade_b") ? Json{s.blade_b.x(), s.blade_b.y(), s.blade_b.z()} : Json(),
           "the blade's two ends must differ");
  return s;
}

void fit_ellipse(Profile& p) {
  double fw = 0, ff = 0, mean = 0;
  std::vector<double> f(p.s.size());
  for (std::size_t i = 0; i < p.s.size(); ++i) {
    const double u = 2 * p.s[i] - 1;
    f[i] = std::sqrt(std::max(0.0, 1 - u * u));
    fw += f[i] * p.w[i], ff += f[i] * f[i], mean += p.w[i];
  }
  if (p.s.empty() || ff <= 0) return;
  mean /= double(p.s.size());
  p.fit_max = fw / ff;
  double res = 0, tot = 0;
  for (std::size_t i = 0; i < p.s.size(); ++i) {
    res += std::pow(p.w[i] - p.fit_max * f[i], 2);
    tot += std::pow(p.w[i] - mean, 2);
  }
  p.r2 = tot > 0 ? 1 - res / tot : 0;
}

std::vector<double> resample(const Profile& p, const std::vector<double>& at) {
  std::vector<double> out(at.size(), 0.0);
  for (std::size_t k = 0; k < at.size(); ++k) {
    const double s = at[k];
    for (std::size_t i = 1; i < p.s.size(); ++i) {
      if (s < p.s[i - 1] || s > p.s[i]) continue;
      const double span = p.s[i] - p.s[i - 1];
      const double a = span > 0 ? (s - p.s[i - 1]) / span : 0;
      out[k] = (1 - a) * p.w[i - 1] + a * p.w[i];
      break;
    }
  }
  return out;
}

}  // namespace conform::scenes
