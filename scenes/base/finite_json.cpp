#include "base/finite_json.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace conform::scenes {
namespace {

// The first non-finite number below `value`: its path into `key`, itself returned (or null).
const nlohmann::json* find_non_finite(const nlohmann::json& value, const std::string& path,
                                      std::string& key) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) {
    key = path.empty() ? "(value)" : path;
    return &value;
  }
  if (value.is_object())
    for (auto it = value.begin(); it != value.end(); ++it)
      if (auto* bad = find_non_finite(*it, path.empty() ? it.key() : path + "." + it.key(), key))
        return bad;
  if (value.is_array())
    for (std::size_t i = 0; i < value.size(); ++i)
      if (auto* bad = find_non_finite(value[i], path + "[" + std::to_string(i) + "]", key))
        return bad;
  return nullptr;
}

}  // namespace

std::string first_non_finite(const nlohmann::json& value, const std::string& key) {
  std::string bad;
  find_non_finite(value, key, bad);
  return bad;
}

void require_finite(const nlohmann::json& value, const std::string& what) {
  std::string key;
  const nlohmann::json* bad = find_non_finite(value, "", key);
  if (!bad) return;
  std::ostringstream why;
  why << what << ": " << key << " is NaN or infinite (" << bad->get<double>() << ")";
  throw std::runtime_error(why.str());
}

}  // namespace conform::scenes
