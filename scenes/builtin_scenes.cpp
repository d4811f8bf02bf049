// The built-in scenes: scene files compiled into the command, so `conform run NAME` needs no
// file. `conform scenes --show NAME` prints one to start a scene file of your own from.
#include <fstream>
#include <sstream>

#include "scene.hpp"

namespace conform::scenes {

const std::vector<SceneKind>& scene_kinds() {
  static const std::vector<SceneKind> kinds = {
      {"tear-opening", &make_tear_opening},
      {"membrane-slit", &make_membrane_slit},
      {"arm-track", &make_arm_track},
      {"cut", &make_cut},
      {"drill", &make_drill},
      {"character", &make_character},
  };
  return kinds;
}

const std::vector<BuiltinScene>& builtin_scenes() {
  static const std::vector<BuiltinScene> scenes = {
      {"tear-opening",
       "the pre-tensioned skinned arm torn by a scalpel: physical opening (Bullet soft body) vs "
       "the geometric opening of Algorithm 2 step 6, profiles over time (default scene)",
       R"json({
  "scene": "tear-opening",
  "description": "The procedural arm as a CGA-skinned Bullet soft body whose links are 20 % shorter at rest than made (pretension), torn along the forearm by a scalpel stroke; the same stroke on the posed mesh alone is opened by Algorithm 2 step 6. Compares the gap-width profiles over time.",
  "seed": 1,
  "duration": 3.0,
  "model": { "resolution": 1 },
  "pose": { "elbow_deg": 0 },
  "material": {
    "pretension": 0.2, "link_stiffness": 0.9, "damping": 0.02, "density": 1.1,
    "target_stiffness": 4000, "target_damping": 40, "kinematic_weight": 2,
    "position_iterations": 4, "margin": 0.005
  },
  "tear": {
    "at": 0.5, "duration": 0.5, "samples": 40,
    "from": [0, 0.0023, 0.3712], "to": [0, 0.0023, 0.4912],
    "blade_a": [0.09, 0, 0], "blade_b": [0.005, 0, 0]
  },
  "geometric": { "amount": 0.01 },
  "profiles": { "snapshots": 6, "points": 41 },
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json"},
      {"membrane-slit",
       "the skin membrane against LEFM: a pinned, pre-stressed sheet slit through its centre "
       "opens as an ellipse of maximum 4 sigma_n a / E",
       R"json({
  "scene": "membrane-slit",
  "description": "A square sheet of skin membrane (SI units) pinned at its border and pre-stressed by material.prestress along its axes is slit through its centre by a topology change on the live Bullet soft body; it settles, and its opening is compared with linear elastic fracture mechanics (plane stress): w_max = 4 sigma_n a / E.",
  "duration": 1.0,
  "sheet": { "width": 0.8, "resolution": 0.0025, "tip_refinement": 16 },
  "slit": { "length": 0.05, "angle_deg": 0, "at": 0.1 },
  "material": { "prestress": [400, 400], "youngs_modulus": 420000, "poisson_ratio": 0.48,
                "thickness": 0.0015, "attachment_stiffness": 0,
                "attachment_normal_stiffness": 0, "tolerance": 0.4, "max_cg_iterations": 4000 },
  "physics": { "dt": 0.016666666666666666, "substeps": 1, "gravity": [0, 0, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 0, "plots": true }
})json"},
      {"arm-track",
       "btMultiBody arm driven by CGA IK along a figure-eight and random waypoints, skin by CGA "
       "skinning; tracking error with/without gravity compensation",
       R"json({
  "scene": "arm-track",
  "description": "A btMultiBody arm (spherical shoulder, revolute elbow; upper arm 0.30 m, forearm 0.25 m) whose torque-limited joint motors follow the closed-form CGA IK solution for a figure-eight and then random waypoints; the procedural arm's skin follows the physical bones through CGA skinning. Runs with and without gravity compensation on the same targets.",
  "seed": 7,
  "model": { "resolution": 1 },
  "arm": {
    "upper_mass": 2.0, "fore_mass": 1.5, "fore_com": 0.14,
    "shoulder_max_torque": 8, "elbow_max_torque": 4,
    "kp": 0.5, "swivel": 0.0, "gravity_compensation": "both"
  },
  "targets": {
    "center": [0.0, -0.25, 0.30],
    "figure_eight": { "width": 0.30, "height": 0.15, "period": 4, "duration": 8 },
    "waypoints": { "count": 6, "move": 0.8, "hold": 0.8,
                   "min_radius": 0.28, "max_radius": 0.50, "cone_deg": 30 }
  },
  "physics": { "dt": 0.016666666666666666, "substeps": 4, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 60, "plots": true }
})json"},
      {"cut",
       "a planar cut through the forearm of the moving soft arm; the pieces keep simulating under "
       "gravity, the hand piece stays skinned to its bones",
       R"json({
  "scene": "cut",
  "description": "The moving procedural arm as a CGA-skinned Bullet soft body (every node pulled toward its skinned target) is cut through the forearm by a plane; both pieces keep simulating under gravity and the hand piece keeps following the wrist and hand bones.",
  "seed": 1,
  "duration": 3.0,
  "model": { "resolution": 1 },
  "pose": { "shoulder_swing_deg": 20, "elbow_deg": 10, "elbow_swing_deg": 40, "period": 2 },
  "material": { "target_stiffness": 4000, "target_damping": 40, "kinematic_weight": 2,
                "damping": 0.02 },
  "cut": { "at": 0.5, "point": [0, 0, 0.4234], "normal": [0, 0.05, 1], "cap": false },
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json"},
      {"drill",
       "a hole drilled through the upper arm, then the arm moves; the hole's rim stays on the skin",
       R"json({
  "scene": "drill",
  "description": "A cylindrical drill (radius 12 mm) goes through both walls of the upper arm of the CGA-skinned soft arm; the arm then swings and flexes, and the rim nodes are measured against their skinned targets.",
  "seed": 1,
  "duration": 3.0,
  "model": { "resolution": 1 },
  "pose": { "shoulder_swing_deg": 20, "elbow_deg": 10, "elbow_swing_deg": 40, "period": 2 },
  "material": { "target_stiffness": 4000, "target_damping": 40, "kinematic_weight": 2,
                "damping": 0.02 },
  "drill": { "at": 0.5, "tip": [0.1, 0.0031, 0.1512], "base": [-0.1, 0.0031, 0.1512],
             "radius": 0.012 },
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json"},
      {"character",
       "a real rigged model (assimp) plays its animation through CGA skinning with soft-body "
       "secondary motion",
       R"json({
  "scene": "character",
  "description": "huesitos.fbx from Debian's assimp-testmodels (9 bones, animated) plays its animation through CGA skinning as a Bullet soft body: nodes close to one bone ride it, blended regions follow their skinned targets softly.",
  "seed": 1,
  "duration": 1.56,
  "model": { "file": "/usr/share/assimp/models/FBX/huesitos.fbx", "animation": "0",
             "units_per_metre": 100 },
  "material": { "link_stiffness": 0.02, "target_stiffness": 2000, "target_damping": 20,
                "kinematic_weight": 0.95, "damping": 0.01 },
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json"},
  };
  return scenes;
}

const BuiltinScene* find_builtin(const std::string& name) {
  for (const auto& s : builtin_scenes())
    if (name == s.name) return &s;
  return nullptr;
}

std::unique_ptr<Scene> load_scene(const std::string& name_or_file,
                                  const std::vector<std::string>& assignments, int steps_override) {
  Json scene;
  std::string name;
  if (const BuiltinScene* b = find_builtin(name_or_file)) {
    scene = Json::parse(b->json);
    name = b->name;
  } else {
    std::ifstream in(name_or_file);
    if (!in) {
      std::string names;
      for (const auto& s : builtin_scenes())
        names += (names.empty() ? "" : ", ") + std::string(s.name);
      throw std::runtime_error("'" + name_or_file + "' is neither a built-in scene (" + names +
                               ") nor a readable scene file");
    }
    try {
      scene = Json::parse(in, nullptr, true, /*ignore_comments=*/true);
    } catch (const Json::parse_error& e) {
      throw std::runtime_error(name_or_file + ": not valid JSON: " + e.what());
    }
    name = std::filesystem::path(name_or_file).stem().string();
  }
  for (const auto& a : assignments) apply_set(scene, a);
  if (!scene.is_object()) throw SceneError("(scene)", show(scene), "must be a JSON object");
  const auto it = scene.find("scene");
  if (it == scene.end()) throw SceneError("scene", "(missing)", "is required: the scene kind");
  std::string kinds;
  for (const auto& k : scene_kinds()) {
    if (it->is_string() && it->get<std::string>() == k.name)
      return k.factory(scene, name, steps_override);
    kinds += (kinds.empty() ? "" : ", ") + std::string(k.name);
  }
  throw SceneError("scene", show(*it), "unknown scene kind (known: " + kinds + ")");
}

}  // namespace conform::scenes
