#include "conform/membrane/crack_growth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "conform/membrane/crack_extension.hpp"
#include "range_error.hpp"

namespace conform::membrane {

void GrowthSettings::validate() const {
  domain.validate();
  const RangeCheck check("crack growth");
  check(std::isfinite(step_length) && step_length > 0, "step_length", step_length, "> 0 m");
  check(max_extensions >= 1, "max_extensions", max_extensions, ">= 1");
  check(snap_fraction >= 0 && snap_fraction < 0.5, "snap_fraction", snap_fraction, "[0, 0.5)");
}

double tip_domain_radius(const mesh::SkinnedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                         std::int32_t tip, double wanted) {
  double nearest = std::numeric_limits<double>::infinity();
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v)
    if (fixed[std::size_t(v)])
      nearest = std::min(nearest, (mesh.rest.col(v) - mesh.rest.col(tip)).norm());
  return std::min(wanted, 0.5 * nearest);
}

Eigen::Vector3d growth_direction(const mesh::SkinnedMesh& mesh, const CrackTip& tip, double kink) {
  const Eigen::Vector3d normal = sheet_normal(mesh, tip.vertex);
  const Eigen::Vector3d e = tip.direction, n = normal.cross(e);
  return std::cos(kink) * e + std::sin(kink) * n;
}

CrackedSheet::CrackedSheet(mesh::SkinnedMesh mesh, std::vector<std::uint8_t> fixed,
                           const std::vector<CrackTip>& tips, const SkinMaterial& material,
                           const SolverSettings& solver)
    : mesh_(std::move(mesh)),
      fixed_(std::move(fixed)),
      material_(material),
      solver_settings_(solver) {
  if (fixed_.size() != std::size_t(mesh_.vertex_count()))
    throw std::invalid_argument("CrackedSheet: " + std::to_string(fixed_.size()) +
                                " fixed flags for " + std::to_string(mesh_.vertex_count()) +
                                " vertices");
  for (const CrackTip& t : tips) {
    if (t.vertex < 0 || t.vertex >= mesh_.vertex_count())
      throw std::invalid_argument("CrackedSheet: tip vertex " + std::to_string(t.vertex) +
                                  " is not a vertex of the mesh");
    tips_.push_back({t, false, 0.0, {mesh_.rest.col(t.vertex)}});
  }
  solver_settings_.validate();
  model_.build(mesh_.rest, mesh_.faces, material_);
  x_ = mesh_.rest;
}

SolveReport CrackedSheet::solve() {
  const Eigen::Matrix3Xd none(3, 0);
  const StepInput input{mesh_.rest, none, none, none, fixed_, 0.0};
  return solver_.solve(model_, input, solver_settings_, x_);
}

bool CrackedSheet::extend(int i, const TipFracture& f, const GrowthSettings& s,
                          GrowthReport& report) {
  GrowingTip& g = tips_[std::size_t(i)];
  const double kink = mts_kink_angle(f.k1, f.k2);
  const Eigen::Vector3d along = growth_direction(mesh_, g.tip, kink);
  const CrackExtension ext = crack_extension(mesh_, fixed_, g.tip.vertex, along, s.snap_fraction);
  if (ext.change.empty()) {
    g.stopped = true;  // the border, or a fan that cannot be split: the tear ends here
    return false;
  }
  const Eigen::Vector3d from = mesh_.rest.col(g.tip.vertex);
  mesh::apply(mesh_, ext.change);
  extend_columns(x_, ext.change);
  fixed_.resize(std::size_t(mesh_.vertex_count()), 0);
  const Eigen::Vector3d to = mesh_.rest.col(ext.new_tip);
  const double length = (to - from).norm();
  g.tip = {ext.new_tip, (to - from) / length};
  g.grown += length;
  g.path.push_back(to);
  report.extensions.push_back({i, f, kink, length});
  report.grown += length;
  return true;
}

GrowthReport CrackedSheet::grow(const GrowthSettings& s) {
  s.validate();
  GrowthReport report;
  for (bool first = true;; first = false) {
    // Every running tip is judged on the same equilibrium before any of them grows.
    std::vector<TipEvaluation> judged;
    for (std::size_t i = 0; i < tips_.size(); ++i) {
      if (tips_[i].stopped) continue;
      EnergyReleaseOptions domain = s.domain;
      domain.domain_radius =
          tip_domain_radius(mesh_, fixed_, tips_[i].tip.vertex, s.domain.domain_radius);
      judged.push_back({int(i), energy_release(mesh_, material_, x_, tips_[i].tip, domain), 0, 0});
    }
    if (first) report.first = judged;
    bool grew = false;
    for (const TipEvaluation& j : judged) {
      const bool budget =
          report.grown < s.step_length && int(report.extensions.size()) < s.max_extensions;
      if (j.fracture.energy_release_rate >= material_.toughness && budget)
        grew = extend(j.tip, j.fracture, s, report) || grew;
    }
    if (!grew) break;
    model_.build(mesh_.rest, mesh_.faces, material_);
    report.solve = solve();
  }
  return report;
}

}  // namespace conform::membrane
