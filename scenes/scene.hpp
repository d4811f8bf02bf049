// Scene kinds of `conform run`: each parses its JSON (strictly, writing nothing) into a
// prepared scene, which then runs into a RunOutput folder. Built-in scenes are JSON texts
// compiled into the command (builtin_scenes.cpp); `conform scenes --show NAME` prints one.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "run_output.hpp"
#include "scene_config.hpp"

namespace conform::scenes {

class Scene {
 public:
  virtual ~Scene() = default;
  const CommonSettings& common() const { return common_; }
  const Json& resolved() const { return resolved_; }
  /// Runs the scene into `out` and returns the summary (also written to summary.json).
  virtual Json run(RunOutput& out) = 0;

 protected:
  CommonSettings common_;
  Json resolved_;
};

/// Parses a scene of one kind. Throws SceneError (nothing is written).
using SceneFactory = std::unique_ptr<Scene> (*)(const Json& scene, const std::string& name,
                                                int steps_override);

struct SceneKind {
  const char* name;
  SceneFactory factory;
};

std::unique_ptr<Scene> make_arm_track(const Json&, const std::string&, int);
std::unique_ptr<Scene> make_tear_opening(const Json&, const std::string&, int);
std::unique_ptr<Scene> make_membrane_slit(const Json&, const std::string&, int);
std::unique_ptr<Scene> make_cut(const Json&, const std::string&, int);
std::unique_ptr<Scene> make_drill(const Json&, const std::string&, int);
std::unique_ptr<Scene> make_character(const Json&, const std::string&, int);

/// The kinds that exist in this build.
const std::vector<SceneKind>& scene_kinds();

struct BuiltinScene {
  const char* name;
  const char* summary;  // one line for `conform scenes`
  const char* json;     // the scene file
};
const std::vector<BuiltinScene>& builtin_scenes();
/// The built-in scene of that name, or nullptr.
const BuiltinScene* find_builtin(const std::string& name);

/// Parses a scene given by built-in name or JSON file path, applies --set assignments, and
/// prepares it. Throws SceneError or std::runtime_error (unreadable file, bad JSON).
std::unique_ptr<Scene> load_scene(const std::string& name_or_file,
                                  const std::vector<std::string>& assignments, int steps_override);

}  // namespace conform::scenes
