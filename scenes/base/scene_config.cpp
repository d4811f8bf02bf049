#include "base/scene_config.hpp"

#include <cmath>

namespace conform::scenes {

const Json Reader::kEmpty = Json::object();

namespace {
constexpr std::size_t kShownChars = 60;
constexpr int kShownDepth = 8;

// Like Json::dump() without spaces, but its recursion stops at kShownDepth levels and once
// the text is longer than what is shown: Json::dump() recurses as deep as the input nests,
// and a scene file nested 100,000 deep overflowed the stack while its error was printed.
void append_shown(const Json& value, int depth, std::string& out) {
  if (!value.is_structured()) {
    // Replace, not throw: a --set value is any bytes, and its error must still print.
    out += value.dump(-1, ' ', false, Json::error_handler_t::replace);
    return;
  }
  const bool array = value.is_array();
  if (depth >= kShownDepth && !value.empty()) {
    out += array ? "[...]" : "{...}";
    return;
  }
  out += array ? '[' : '{';
  bool first = true;
  for (auto it = value.begin(); it != value.end() && out.size() <= kShownChars; ++it) {
    if (!first) out += ',';
    first = false;
    if (!array) out += Json(it.key()).dump(-1, ' ', false, Json::error_handler_t::replace) + ':';
    append_shown(it.value(), depth + 1, out);
  }
  out += array ? ']' : '}';
}
}  // namespace

std::string show(const Json& value) {
  std::string s;
  append_shown(value, 0, s);
  if (s.size() > kShownChars) s = s.substr(0, kShownChars - 3) + "...";
  return s;
}

Reader::Reader(const Json& object, std::string path, Json& resolved)
    : object_(&object), path_(std::move(path)), resolved_(&resolved) {
  if (!object.is_object())
    throw SceneError(path_.empty() ? "(scene)" : path_, show(object), "must be a JSON object");
  if (!resolved_->is_object()) *resolved_ = Json::object();
}

void Reader::fail(const std::string& key, const Json& value, const std::string& reason) const {
  throw SceneError(dotted(key), show(value), reason);
}

const Json* Reader::get(const std::string& key) {
  mark(key);
  const auto it = object_->find(key);
  return it == object_->end() ? nullptr : &*it;
}

namespace {
std::string range_text(double min, double max) {
  const auto fmt = [](double v) {
    Json j = v;
    return j.dump();
  };
  if (std::isinf(min)) return "must be at most " + fmt(max);
  if (std::isinf(max)) return "must be at least " + fmt(min);
  return "must be in [" + fmt(min) + ", " + fmt(max) + "]";
}
}  // namespace

double Reader::finite(const std::string& key, const Json& value, const Json& c,
                      const std::string& reason) const {
  if (!c.is_number() || !std::isfinite(c.get<double>())) fail(key, value, reason);
  return c.get<double>();
}

double Reader::number(const std::string& key, double fallback, double min, double max) {
  const Json* v = get(key);
  double x = fallback;
  if (v) {
    if (!v->is_number()) fail(key, *v, "must be a number");
    x = finite(key, *v, *v, "must be finite");
    if (x < min || x > max) fail(key, *v, range_text(min, max));
  }
  (*resolved_)[key] = x;
  return x;
}

double Reader::required_number(const std::string& key, double min, double max) {
  if (!has(key)) fail(key, Json(nullptr), "is required");
  return number(key, 0, min, max);
}

int Reader::integer(const std::string& key, int fallback, int min, int max) {
  const Json* v = get(key);
  int x = fallback;
  if (v) {
    if (!v->is_number_integer() &&
        !(v->is_number_float() && std::floor(v->get<double>()) == v->get<double>()))
      fail(key, *v, "must be an integer");
    const double d = v->get<double>();
    if (d < min || d > max) fail(key, *v, range_text(min, max));
    x = static_cast<int>(d);
  }
  (*resolved_)[key] = x;
  return x;
}

bool Reader::boolean(const std::string& key, bool fallback) {
  const Json* v = get(key);
  bool x = fallback;
  if (v) {
    if (!v->is_boolean()) fail(key, *v, "must be true or false");
    x = v->get<bool>();
  }
  (*resolved_)[key] = x;
  return x;
}

std::string Reader::text(const std::string& key, const std::string& fallback,
                         std::initializer_list<const char*> allowed) {
  const Json* v = get(key);
  std::string x = fallback;
  if (v) {
    if (!v->is_string()) fail(key, *v, "must be a string");
    x = v->get<std::string>();
    if (allowed.size() > 0) {
      bool ok = false;
      std::string list;
      for (const char* a : allowed) {
        ok = ok || x == a;
        list += (list.empty() ? "" : ", ") + std::string(a);
      }
      if (!ok) fail(key, *v, "must be one of: " + list);
    }
  }
  (*resolved_)[key] = x;
  return x;
}

Eigen::Vector3d Reader::vec3(const std::string& key, const Eigen::Vector3d& fallback,
                             double max_norm) {
  const Json* v = get(key);
  Eigen::Vector3d x = fallback;
  if (v) {
    if (!v->is_array() || v->size() != 3) fail(key, *v, "must be an array of 3 numbers");
    for (int i = 0; i < 3; ++i)
      x[i] = finite(key, *v, (*v)[static_cast<std::size_t>(i)],
                    "must be an array of 3 finite numbers");
    // The norm of finite components can still overflow: compare the largest one first.
    if (x.cwiseAbs().maxCoeff() > max_norm || x.norm() > max_norm)
      fail(key, *v, "its length must be at most " + Json(max_norm).dump());
  }
  (*resolved_)[key] = {x.x(), x.y(), x.z()};
  return x;
}

std::array<double, 2> Reader::pair(const std::string& key, const std::array<double, 2>& fallback,
                                   double min, double max) {
  const Json* v = get(key);
  std::array<double, 2> x = fallback;
  if (v) {
    if (!v->is_array() || v->size() != 2) fail(key, *v, "must be an array of 2 numbers");
    for (std::size_t i = 0; i < 2; ++i) {
      x[i] = finite(key, *v, (*v)[i], "must be an array of 2 finite numbers");
      if (x[i] < min || x[i] > max) fail(key, *v, range_text(min, max));
    }
  }
  (*resolved_)[key] = {x[0], x[1]};
  return x;
}

Reader Reader::object(const std::string& key) {
  const Json* v = get(key);
  if (v && !v->is_object()) fail(key, *v, "must be a JSON object");
  return Reader(v ? *v : kEmpty, dotted(key), (*resolved_)[key]);
}

void Reader::finish() const {
  for (auto it = object_->begin(); it != object_->end(); ++it) {
    if (used_.count(it.key())) continue;
    std::string known;
    for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
    throw SceneError(
        dotted(it.key()), show(it.value()),
        "unknown key" + (known.empty() ? std::string() : " (known here: " + known + ")"));
  }
}

void apply_set(Json& scene, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError(assignment, "(none)", "--set needs KEY=VALUE");
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  // Scene text is UTF-8 (the JSON parser refuses anything else); so must a --set KEY=VALUE be,
  // or its error, and summary.json at the end of the run, could not be written.
  try {
    (void)Json(assignment).dump();
  } catch (const Json::type_error&) {
    throw SceneError(key, "(not shown)", "--set KEY=VALUE must be UTF-8 text");
  }
  Json value = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) value = text;
  Json* node = &scene;
  std::size_t start = 0;
  while (true) {
    const auto dot = key.find('.', start);
    const std::string part =
        key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (part.empty()) throw SceneError(key, show(value), "empty component in the key");
    if (!node->is_object()) {
      if (!node->is_null())
        throw SceneError(key, show(value),
                         "'" + part + "' is inside a value that is not an object");
      *node = Json::object();
    }
    node = &(*node)[part];
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  *node = value;
}

}  // namespace conform::scenes
