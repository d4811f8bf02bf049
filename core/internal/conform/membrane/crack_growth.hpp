// A membrane sheet whose tears grow by themselves: Griffith's criterion on the energy release
// rate (energy_release.hpp) against the material's toughness G_c, quasi-statically.
//
// grow() evaluates G at every tip still running, at the current equilibrium. Where G >= G_c
// the tip extends by one step of crack_extension.hpp in the direction of the maximum tangential
// stress (Erdogan-Sih: theta = mts_kink_angle(K_I, K_II) from the crack's direction), the
// membrane is rebuilt from the rest mesh and solved again, and the tips are evaluated again:
// until no tip has G >= G_c, or the call's budget (a length grown, a number of extensions) is
// spent. A tip that reaches the border stops for good.
//
// The static equilibrium: no inertia, damping or attachment terms beyond the material's (a flat
// sheet held by its pinned vertices; their positions are the caller's load).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "conform/membrane/energy_release.hpp"
#include "conform/membrane/model.hpp"
#include "conform/membrane/solver.hpp"

namespace conform::membrane {

struct GrowthSettings {
  /// The domain of G around each tip; its radius is further held below half the tip's distance
  /// to the nearest fixed vertex.
  EnergyReleaseOptions domain;
  double step_length = 0.01;    // growth per call (all tips), m, > 0: one extension may pass it
  int max_extensions = 64;      // per call, >= 1
  double snap_fraction = 0.15;  // crack_extension.hpp, in [0, 0.5)
  /// Throws std::invalid_argument naming a field out of its range.
  void validate() const;
};

struct GrowingTip {
  CrackTip tip;
  bool stopped = false;               // reached the border
  double grown = 0;                   // rest-space length of the path grown so far, m
  std::vector<Eigen::Vector3d> path;  // rest positions of the tip, from its start
};

struct TipEvaluation {
  int tip = 0;  // index into CrackedSheet::tips()
  TipFracture fracture;
  double kink = 0;    // direction chosen (MTS) relative to the crack's, rad; 0 without growth
  double length = 0;  // the extension, m; 0 without growth
};

struct GrowthReport {
  std::vector<TipEvaluation> first;       // every running tip, at the state grow() was given
  std::vector<TipEvaluation> extensions;  // every extension made, in order
  double grown = 0;                       // this call's total, m
  SolveReport solve;                      // the last solve (after the last extension)
};

/// The largest domain radius <= wanted around `tip` whose q vanishes on every fixed vertex
/// (half the rest distance to the nearest one): the load is held there.
double tip_domain_radius(const mesh::SkinnedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                         std::int32_t tip, double wanted);

/// The direction the tip grows in (rest space, in the sheet's plane): the crack's direction e
/// turned by `kink` (mts_kink_angle) toward n = N x e, N the sheet's normal at the tip.
Eigen::Vector3d growth_direction(const mesh::SkinnedMesh& mesh, const CrackTip& tip, double kink);

class CrackedSheet {
 public:
  /// `mesh`: the sheet with its cracks already made (rest positions; current ones unused);
  /// `fixed`: one flag per vertex; `tips`: the cracks' tips. Positions start at rest.
  CrackedSheet(mesh::SkinnedMesh mesh, std::vector<std::uint8_t> fixed,
               const std::vector<CrackTip>& tips, const SkinMaterial& material,
               const SolverSettings& solver);

  /// The deformed positions (3 x #V): set the fixed vertices' to load the sheet.
  Eigen::Matrix3Xd& positions() { return x_; }
  const Eigen::Matrix3Xd& positions() const { return x_; }
  /// The static equilibrium from the current positions.
  SolveReport solve();
  /// Griffith's growth at the current state (see the top of this file); x must be solved.
  GrowthReport grow(const GrowthSettings& settings);

  const mesh::SkinnedMesh& mesh() const { return mesh_; }
  const std::vector<GrowingTip>& tips() const { return tips_; }
  const std::vector<std::uint8_t>& fixed() const { return fixed_; }
  const SkinMaterial& material() const { return material_; }

 private:
  // One extension of tip i along its MTS direction; false when it stopped.
  bool extend(int i, const TipFracture& f, const GrowthSettings& s, GrowthReport& report);

  mesh::SkinnedMesh mesh_;
  std::vector<std::uint8_t> fixed_;
  std::vector<GrowingTip> tips_;
  SkinMaterial material_;
  SolverSettings solver_settings_;
  Model model_;
  Solver solver_;
  Eigen::Matrix3Xd x_;
};

}  // namespace conform::membrane
