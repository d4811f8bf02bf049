#include "sweep/sweep_grid.hpp"

#include <set>

namespace conform::scenes {

std::vector<std::string> SweepPoint::assignments() const {
  std::vector<std::string> out;
  for (const auto& [key, value] : values) out.push_back(key + "=" + value);
  if (seed > 0) out.push_back("seed=" + std::to_string(seed));
  return out;
}

std::string SweepPoint::label() const {
  std::string s;
  for (const auto& [key, value] : values) s += (s.empty() ? "" : ", ") + key + "=" + value;
  if (seed > 0)
    s += (s.empty() ? "seed " : " (seed ") + std::to_string(seed) + (s.empty() ? "" : ")");
  return s.empty() ? "(the scene as it is)" : s;
}

namespace {

// Splits at commas outside brackets and quotes: "[1,2],[3,4]" is two values.
std::vector<std::string> split_values(const std::string& text) {
  std::vector<std::string> out;
  std::string current;
  int depth = 0;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '\\' && i + 1 < text.size())
        current += text[i++];
      else if (c == '"')
        quoted = false;
    } else if (c == '"') {
      quoted = true;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    } else if (c == ',' && depth == 0) {
      out.push_back(current);
      current.clear();
      continue;
    }
    current += c;
  }
  out.push_back(current);
  return out;
}

}  // namespace

SweepAxis parse_axis(const std::string& option, const std::string& spec, bool zipped) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError(spec, "(none)", option + " needs KEY=V1,V2,...");
  SweepAxis axis;
  axis.key = spec.substr(0, eq);
  axis.zipped = zipped;
  axis.values = split_values(spec.substr(eq + 1));
  std::set<std::string> seen;
  for (const auto& v : axis.values) {
    if (v.empty()) throw SceneError(axis.key, "\"\"", option + " has an empty value in " + spec);
    if (!seen.insert(v).second) throw SceneError(axis.key, v, option + " lists this value twice");
  }
  return axis;
}

std::vector<SweepPoint> expand(const std::vector<SweepAxis>& axes, int repeat) {
  std::set<std::string> keys;
  std::size_t zip_length = 0;
  const SweepAxis* first_zip = nullptr;
  for (const auto& a : axes) {
    if (!keys.insert(a.key).second) throw SceneError(a.key, "(axis)", "is swept twice");
    if (a.key == "seed" && repeat > 1)
      throw SceneError("seed", "(axis)", "cannot be swept with --repeat (which sets the seed)");
    if (!a.zipped) continue;
    if (first_zip && a.values.size() != zip_length)
      throw SceneError(a.key, std::to_string(a.values.size()) + " values",
                       "--zip axes must have the same length (" + first_zip->key + " has " +
                           std::to_string(zip_length) + ")");
    first_zip = first_zip ? first_zip : &a;
    zip_length = a.values.size();
  }
  // Odometer over the grid axes and the one zipped axis; the last axis varies fastest.
  std::vector<std::size_t> lengths;
  for (const auto& a : axes)
    if (!a.zipped) lengths.push_back(a.values.size());
  if (first_zip) lengths.push_back(zip_length);
  double total = repeat;
  for (auto n : lengths) total *= double(n);
  if (total > kMaxSweepPoints)
    throw SceneError("(grid)", std::to_string(static_cast<long long>(total)) + " points",
                     "more than the limit of " + std::to_string(kMaxSweepPoints));
  std::vector<SweepPoint> points;
  std::vector<std::size_t> at(lengths.size(), 0);
  while (true) {
    SweepPoint base;
    std::size_t g = 0;
    for (const auto& a : axes) {
      const std::size_t i = a.zipped ? at.back() : at[g++];
      base.values.emplace_back(a.key, a.values[i]);
    }
    for (int r = 0; r < repeat; ++r) {
      SweepPoint p = base;
      p.index = static_cast<int>(points.size());
      p.repeat = r;
      p.seed = repeat > 1 ? static_cast<std::uint64_t>(r + 1) : 0;
      points.push_back(std::move(p));
    }
    std::size_t d = lengths.size();
    while (d > 0 && ++at[d - 1] == lengths[d - 1]) at[--d] = 0;
    if (d == 0) break;
  }
  return points;
}

}  // namespace conform::scenes
