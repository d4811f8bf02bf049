#include "sweep/sweep_spec.hpp"

#include <cstdio>
#include <fstream>

#include "base/bounded_read.hpp"
#include "kinds/scene.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

std::vector<std::string> SweepSpec::run_arguments(const SweepPoint& p, const fs::path& out) const {
  std::vector<std::string> args = {"run", scene, "--out", out.string()};
  if (steps > 0) args.insert(args.end(), {"--steps", std::to_string(steps)});
  for (const auto& s : sets) args.insert(args.end(), {"--set", s});
  for (const auto& s : p.assignments()) args.insert(args.end(), {"--set", s});
  return args;
}

fs::path point_dir(const fs::path& dir, int index) {
  char name[16];
  std::snprintf(name, sizeof name, "%05d", index);
  return dir / "runs" / name;
}

Json to_json(const SweepSpec& spec) {
  Json j;
  j["command"] = spec.command;
  j["version"] = spec.version;
  j["scene"] = spec.scene;
  j["kind"] = spec.kind;
  j["steps"] = spec.steps;
  j["sets"] = spec.sets;
  j["repeat"] = spec.repeat;
  j["plot"] = spec.plot;
  j["grid"] = Json::array();
  for (const auto& a : spec.axes)
    j["grid"].push_back({{"key", a.key}, {"values", a.values}, {"zip", a.zipped}});
  j["points"] = Json::array();
  for (const auto& p : spec.points) {
    Json values = Json::object();
    for (const auto& [k, v] : p.values) values[k] = v;
    j["points"].push_back({{"index", p.index},
                           {"folder", point_dir("", p.index).string()},
                           {"values", values},
                           {"repeat", p.repeat},
                           {"seed", p.seed},
                           {"run_seed", p.run_seed}});
  }
  return j;
}

namespace {

SweepSpec from_json(const Json& j) {
  SweepSpec s;
  s.command = j.at("command").get<std::string>();
  s.version = j.at("version").get<std::string>();
  s.scene = j.at("scene").get<std::string>();
  s.kind = j.at("kind").get<std::string>();
  s.steps = j.at("steps").get<int>();
  s.sets = j.at("sets").get<std::vector<std::string>>();
  s.repeat = j.at("repeat").get<int>();
  s.plot = j.at("plot").get<std::vector<std::string>>();
  for (const auto& a : j.at("grid"))
    s.axes.push_back({a.at("key").get<std::string>(),
                      a.at("values").get<std::vector<std::string>>(), a.at("zip").get<bool>()});
  for (const auto& p : j.at("points")) {
    SweepPoint point;
    point.index = p.at("index").get<int>();
    if (point.index != static_cast<int>(s.points.size()))
      throw std::runtime_error("point " + std::to_string(point.index) + " is out of order");
    // The values in axis order (JSON objects are stored sorted by key).
    for (const auto& a : s.axes)
      point.values.emplace_back(a.key, p.at("values").at(a.key).get<std::string>());
    point.repeat = p.at("repeat").get<int>();
    point.seed = p.at("seed").get<std::uint64_t>();
    point.run_seed = p.at("run_seed").get<std::uint64_t>();
    s.points.push_back(std::move(point));
  }
  return s;
}

}  // namespace

SweepSpec read_spec(const fs::path& dir) {
  const fs::path file = dir / "sweep.json";
  std::string text;
  try {
    text = read_bounded(file.string(), "sweep file");
  } catch (const InputMissing&) {
    throw std::runtime_error(file.string() + ": cannot read (is this a sweep folder?)");
  }
  try {
    return from_json(Json::parse(text));
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": not a sweep description: " + e.what());
  }
}

void write_spec(const fs::path& dir, const SweepSpec& spec) {
  const fs::path file = dir / "sweep.json", tmp = dir / ".sweep.json.tmp";
  {
    std::ofstream out(tmp);
    out << to_json(spec).dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, file);
}

void validate_points(SweepSpec& spec) {
  for (auto& p : spec.points) {
    std::vector<std::string> sets = spec.sets;
    for (const auto& a : p.assignments()) sets.push_back(a);
    try {
      const auto scene = load_scene(spec.scene, sets, spec.steps);
      spec.kind = scene->common().kind;
      p.run_seed = scene->common().seed;
    } catch (const SceneError& e) {
      throw SceneError(e.key(), e.value(),
                       e.reason() + " (point " + std::to_string(p.index) + ": " + p.label() + ")");
    }
  }
}

bool same_runs(const SweepSpec& a, const SweepSpec& b) {
  if (a.scene != b.scene || a.steps != b.steps || a.sets != b.sets ||
      a.points.size() != b.points.size())
    return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i].assignments() != b.points[i].assignments()) return false;
  return true;
}

}  // namespace conform::scenes
