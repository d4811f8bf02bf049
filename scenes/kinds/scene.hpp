// Scene kinds of `conform run`: each parses its JSON (strictly, writing nothing) into a
// prepared scene, which then runs into a RunOutput folder. Each kind's file holds its default
// JSON (the built-in scene of the same name) and registers both (scene_registry.cpp keeps
// the list); `conform scenes --show NAME` prints one.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/scene_config.hpp"
#include "kinds/run_output.hpp"

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

/// A scene kind and its built-in scene of the same name: the scene's own file registers it
/// (see SceneRegistration), so adding a scene is adding one file.
struct SceneKind {
  const char* name;
  const char* summary;  // one line for `conform scenes`
  const char* json;     // the built-in scene file (`conform scenes --show NAME`)
  SceneFactory factory;
  int rank;  // position in `conform scenes` (smaller first)
  /// The metrics `conform sweep` plots by default: comma-separated keys of summary.json's
  /// "metrics", nested keys dotted (e.g. "physics.max_opening").
  const char* headline = "";
};

/// A built-in scene's text put together from blocks, so that a block several scenes share (the
/// arm of cut and drill, the pinned sheet of membrane-slit and membrane-hole) is written once:
/// the blocks joined as they are, so the text is the one a single literal would give.
inline std::string join_scene_json(std::initializer_list<std::string_view> blocks) {
  std::string text;
  for (const std::string_view block : blocks) text += block;
  return text;
}

/// Registers a scene kind during static initialisation. In the scene's file:
///   const SceneRegistration kRegistration{{"name", "summary", kJson, &make, rank}};
struct SceneRegistration {
  explicit SceneRegistration(const SceneKind& kind);
};

/// The registered kinds, by rank (complete once main() runs).
const std::vector<SceneKind>& scene_kinds();
/// The scene kind of that name, or nullptr.
const SceneKind* find_builtin(const std::string& name);

/// Parses a scene given by built-in name or JSON file path, applies --set assignments, and
/// prepares it. Throws SceneError or std::runtime_error (unreadable file, bad JSON).
std::unique_ptr<Scene> load_scene(const std::string& name_or_file,
                                  const std::vector<std::string>& assignments, int steps_override);
/// The same for the text of a scene file (`file` names it in errors and gives the scene's name).
std::unique_ptr<Scene> load_scene_text(std::string_view text, const std::string& file,
                                       const std::vector<std::string>& assignments,
                                       int steps_override);
/// The same for parsed JSON: --set assignments, the kind's factory. Throws SceneError.
std::unique_ptr<Scene> prepare_scene(Json scene, const std::string& name,
                                     const std::vector<std::string>& assignments,
                                     int steps_override);

}  // namespace conform::scenes
