// Fuzz target: the scene parser, from a scene file's text to a prepared scene, as `conform run`
// reads it (scenes/kinds/scene.hpp: load_scene_text; nothing runs and nothing is written). Input:
// optional first lines "set KEY=VALUE" (the command line's --set), then the JSON text.
// Properties, for any text:
//   - the parser refuses it with SceneError or std::runtime_error (a message naming the key,
//     or the JSON error), never another exception (a nlohmann type error means a value was
//     read without its type checked), a crash or undefined behaviour;
//   - a scene it accepts holds only finite numbers in its resolved settings (what
//     summary.json records), and a step count in [1, 1e8].
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_bytes.hpp"
#include "kinds/scene.hpp"

using namespace conform;

namespace {

// The JSON path of the first non-finite number in `value` ("" when none).
std::string first_non_finite(const scenes::Json& value, const std::string& path) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) return path + " ";
  if (value.is_structured())
    for (auto it = value.begin(); it != value.end(); ++it)
      if (auto bad = first_non_finite(*it, path + "/" + (value.is_object() ? it.key() : "#"));
          !bad.empty())
        return bad;
  return {};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> sets;
  while (text.rfind("set ", 0) == 0) {
    const std::size_t end = text.find('\n');
    sets.push_back(text.substr(4, end == std::string::npos ? std::string::npos : end - 4));
    text.erase(0, end == std::string::npos ? text.size() : end + 1);
  }
  std::unique_ptr<scenes::Scene> scene;
  try {
    scene = scenes::load_scene_text(text, "fuzz.json", sets, 0);
  } catch (const std::runtime_error&) {
    return 0;  // SceneError, or the JSON's own error: a message for the user
  } catch (const std::exception& e) {
    fuzz::fuzz_require(false, std::string("the parser threw a non-user error: ") + e.what());
  }
  const std::string bad = first_non_finite(scene->resolved(), "");
  fuzz::fuzz_require(bad.empty(), "an accepted scene holds a non-finite number at " + bad);
  const int steps = scene->common().steps;
  fuzz::fuzz_require(steps >= 1 && steps <= 100000000,
                     "an accepted scene has " + std::to_string(steps) + " steps");
  return 0;
}
