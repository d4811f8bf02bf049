#include "kinds/membrane_check.hpp"

#include <cmath>

namespace conform::scenes {

skin::Skeleton one_bone() {
  skin::Skeleton s;
  s.joints.push_back({"root", -1, skin::Versor::identity()});
  s.bones.push_back({"root", 0, skin::Versor::identity()});
  return s;
}

std::vector<std::int32_t> flagged_vertices(const std::vector<std::uint8_t>& flags) {
  std::vector<std::int32_t> out;
  for (std::size_t v = 0; v < flags.size(); ++v)
    if (flags[v]) out.push_back(std::int32_t(v));
  return out;
}

Foundation foundation(const membrane::SkinMaterial& m) {
  Foundation f;
  f.plane_modulus = m.youngs_modulus / (1 - m.poisson_ratio * m.poisson_ratio);
  const double k = m.attachment_stiffness;
  f.decay_length = k > 0 ? std::sqrt(f.plane_modulus * m.thickness / k) : 0.0;
  return f;
}

Json solver_metrics(const membrane::SolveReport& last, double settled_at, const CommonSettings& c) {
  return {{"residual", last.residual},
          {"relative_residual", last.relative_residual},
          {"converged", last.converged},
          {"settled_at", settled_at},
          {"settled", settled_at < c.steps * c.dt - 0.5 * c.dt}};
}

}  // namespace conform::scenes
