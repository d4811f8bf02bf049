// Scene files: JSON parsed with nlohmann-json, read strictly. Every scene kind reads its keys
// through a Reader, which checks types and ranges, fills in defaults, records the values it
// used (for summary.json) and rejects keys nobody read. A problem throws SceneError naming the
// key (as a dotted path), the value and the reason; nothing is written before parsing is done.
#pragma once

#include <Eigen/Core>
#include <array>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace conform::scenes {

using Json = nlohmann::json;

class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& key, const std::string& value, const std::string& reason)
      : std::runtime_error("key '" + key + "', value " + value + ": " + reason),
        key_(key),
        value_(value),
        reason_(reason) {}
  const std::string& key() const { return key_; }
  const std::string& value() const { return value_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string key_, value_, reason_;
};

/// A short printable form of a JSON value for error messages: at most 60 characters, and
/// nesting below 8 levels shown as [...] or {...}, so any input prints in bounded time and stack.
std::string show(const Json& value);

/// Strict reader of one JSON object. `resolved` receives every value read (defaults included).
class Reader {
 public:
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  Reader(const Json& object, std::string path, Json& resolved);

  bool has(const std::string& key) const { return object_->contains(key); }
  /// True when the key is present and a boolean (a key that is a switch or an object).
  bool is_boolean(const std::string& key) const {
    return has(key) && object_->at(key).is_boolean();
  }
  /// True when the key is present and a string (a key that is a number or a name).
  bool is_text(const std::string& key) const { return has(key) && object_->at(key).is_string(); }
  double number(const std::string& key, double fallback, double min = -kInf, double max = kInf);
  /// Like number() but the key must be present.
  double required_number(const std::string& key, double min = -kInf, double max = kInf);
  int integer(const std::string& key, int fallback, int min, int max);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback,
                   std::initializer_list<const char*> allowed = {});
  /// An array of 3 finite numbers whose length is at most `max_norm`.
  Eigen::Vector3d vec3(const std::string& key, const Eigen::Vector3d& fallback,
                       double max_norm = kInf);
  /// An array of exactly two numbers, each in [min, max].
  std::array<double, 2> pair(const std::string& key, const std::array<double, 2>& fallback,
                             double min = -kInf, double max = kInf);
  /// A sub-object (an empty one when absent); it must be finished by the caller.
  Reader object(const std::string& key);
  /// An array of objects (empty when absent), each read through the callback.
  template <class F>
  void objects(const std::string& key, F&& each) {
    mark(key);
    if (!object_->contains(key)) {
      (*resolved_)[key] = Json::array();
      return;
    }
    const Json& a = object_->at(key);
    if (!a.is_array()) fail(key, a, "must be an array of objects");
    (*resolved_)[key] = Json::array();
    for (std::size_t i = 0; i < a.size(); ++i) {
      (*resolved_)[key].push_back(Json::object());
      Reader r(a[i], dotted(key) + "[" + std::to_string(i) + "]", (*resolved_)[key].back());
      each(r);
      r.finish();
    }
  }
  /// Throws for the first key that was not read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const Json& value,
                         const std::string& reason) const;
  std::string dotted(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

 private:
  void mark(const std::string& key) { used_.insert(key); }
  /// The one finiteness check of every number read: `c` is `value` or one of its elements.
  double finite(const std::string& key, const Json& value, const Json& c,
                const std::string& reason) const;
  const Json* get(const std::string& key);

  const Json* object_;
  std::string path_;
  Json* resolved_;
  std::set<std::string> used_;
  static const Json kEmpty;
};

/// Applies `KEY=VALUE` (KEY a dotted path, e.g. physics.dt=0.005) to `scene`. VALUE is read as
/// JSON when it parses (numbers, true, [1,2,3]) and as a string otherwise. Creates missing
/// objects on the way; the strict reader then rejects keys that do not exist.
void apply_set(Json& scene, const std::string& assignment);

}  // namespace conform::scenes
