// The scene registry: every scene file registers its kind and built-in scene here during
// static initialisation (SceneRegistration), and `conform run NAME` finds it by name, so a
// new scene needs no edit outside its own file.
#include <algorithm>

#include "base/bounded_read.hpp"
#include "kinds/scene.hpp"

namespace conform::scenes {
namespace {

// Function-local so that registrations from other files' static initialisers find it built.
std::vector<SceneKind>& registered() {
  static std::vector<SceneKind> kinds;
  return kinds;
}

}  // namespace

SceneRegistration::SceneRegistration(const SceneKind& kind) {
  registered().push_back(kind);
}

const std::vector<SceneKind>& scene_kinds() {
  static const std::vector<SceneKind> sorted = [] {
    std::vector<SceneKind> kinds = registered();
    std::stable_sort(kinds.begin(), kinds.end(),
                     [](const SceneKind& a, const SceneKind& b) { return a.rank < b.rank; });
    return kinds;
  }();
  return sorted;
}

const SceneKind* find_builtin(const std::string& name) {
  for (const auto& s : scene_kinds())
    if (name == s.name) return &s;
  return nullptr;
}

std::unique_ptr<Scene> load_scene(const std::string& name_or_file,
                                  const std::vector<std::string>& assignments, int steps_override) {
  if (const SceneKind* b = find_builtin(name_or_file))
    return prepare_scene(Json::parse(b->json), b->name, assignments, steps_override);
  std::string text;
  try {
    text = read_bounded(name_or_file, "scene file");
  } catch (const InputMissing&) {
    std::string names;
    for (const auto& s : scene_kinds()) names += (names.empty() ? "" : ", ") + std::string(s.name);
    throw std::runtime_error("'" + name_or_file + "' is neither a built-in scene (" + names +
                             ") nor a readable scene file");
  }
  return load_scene_text(text, name_or_file, assignments, steps_override);
}

std::unique_ptr<Scene> load_scene_text(std::string_view text, const std::string& file,
                                       const std::vector<std::string>& assignments,
                                       int steps_override) {
  Json scene;
  try {
    scene = Json::parse(text, nullptr, true, /*ignore_comments=*/true);
  } catch (const Json::exception& e) {  // parse_error, and out_of_range for 1e400
    throw std::runtime_error(file + ": not valid JSON: " + e.what());
  }
  return prepare_scene(std::move(scene), std::filesystem::path(file).stem().string(), assignments,
                       steps_override);
}

std::unique_ptr<Scene> prepare_scene(Json scene, const std::string& name,
                                     const std::vector<std::string>& assignments,
                                     int steps_override) {
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
