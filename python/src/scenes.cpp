// Scenes from Python: conform.run runs a scene in this process exactly as `conform run` does
// (the same parse, output folder and summary), conform.sweep runs the points of a parameter
// sweep (the sweep library's grid) one after the other in this process.
#include <omp.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/output_folder.hpp"
#include "bindings.hpp"
#include "kinds/scene.hpp"
#include "sweep/sweep_grid.hpp"
#include "sweep/sweep_spec.hpp"

namespace conform::python {
namespace {

namespace fs = std::filesystem;

// A --set value as text: a str as it is, anything else as JSON (json.dumps).
std::string set_value(const py::handle& value) {
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  return py::module_::import("json").attr("dumps")(value).cast<std::string>();
}

// The --set assignments of a dict {key: value} (None: none).
std::vector<std::string> assignments(const py::object& sets) {
  std::vector<std::string> out;
  if (sets.is_none()) return out;
  for (const auto& [key, value] : sets.cast<py::dict>())
    out.push_back(py::str(key).cast<std::string>() + "=" + set_value(value));
  return out;
}

py::object to_python(const scenes::Json& json) {
  return py::module_::import("json").attr("loads")(json.dump());
}

// Every "file" key of the resolved scene: the results must not replace a folder holding one.
void collect_inputs(const scenes::Json& j, std::vector<fs::path>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (j.is_object() && it.key() == "file" && it->is_string())
      out.emplace_back(it->get<std::string>());
    if (it->is_structured()) collect_inputs(*it, out);
  }
}

// Runs a prepared scene into `dir` as `conform run` does; the summary written there.
scenes::Json run_into(const std::string& scene, const std::vector<std::string>& sets, int steps,
                      const fs::path& dir) {
  auto prepared = scenes::load_scene(scene, sets, steps);
  const auto& c = prepared->common();
  if (c.threads > 0) omp_set_num_threads(c.threads);
  std::vector<fs::path> inputs;
  if (!scenes::find_builtin(scene)) inputs.emplace_back(scene);
  collect_inputs(prepared->resolved(), inputs);
  scenes::OutputFolder folder(dir, inputs);
  {
    scenes::RunOutput out(folder.staging(), c);
    prepared->run(out);
  }
  folder.commit();
  std::ifstream in(dir / "summary.json");
  scenes::Json summary = scenes::Json::parse(in, nullptr, false);
  if (summary.is_discarded())
    throw std::runtime_error((dir / "summary.json").string() + ": not valid JSON");
  return summary;
}

// `out` or, when None, a fresh temporary folder (removed after the run).
struct OutDir {
  fs::path path;
  bool temporary = false;
  explicit OutDir(const py::object& out) {
    if (!out.is_none()) {
      path = fs::path(py::str(out).cast<std::string>());
      return;
    }
    path = fs::path(
        py::module_::import("tempfile").attr("mkdtemp")("", "conform-").cast<std::string>());
    fs::remove(path);  // the output folder must be new or an earlier result
    temporary = true;
  }
  ~OutDir() {
    std::error_code ec;
    if (temporary) fs::remove_all(path, ec);
  }
};

py::object run(const std::string& scene, const py::object& out, const py::object& sets,
               const py::object& steps, const py::object& render) {
  std::vector<std::string> s = assignments(sets);
  if (!render.is_none() && !render.cast<bool>()) s.push_back("render=false");
  const int n = steps.is_none() ? 0 : steps.cast<int>();
  if (n < 0 || n > scenes::kMaxSteps)
    throw std::invalid_argument("steps = " + std::to_string(n) + " is out of range [1, " +
                                std::to_string(scenes::kMaxSteps) + "]");
  OutDir dir(out);
  scenes::Json summary;
  {
    py::gil_scoped_release release;
    summary = run_into(scene, s, n, dir.path);
  }
  return to_python(summary);
}

py::list scene_names() {
  py::list names;
  for (const auto& k : scenes::scene_kinds()) names.append(k.name);
  return names;
}

std::string scene_json(const std::string& name) {
  const auto* kind = scenes::find_builtin(name);
  if (!kind) throw std::invalid_argument("no built-in scene '" + name + "'");
  return kind->json;
}

// The sweep's axes: grid {key: [values]} as a product, zip {key: [values]} advanced together.
std::vector<scenes::SweepAxis> sweep_axes(const py::object& grid, const py::object& zip) {
  std::vector<scenes::SweepAxis> axes;
  for (const auto& [axes_of, zipped] : {std::pair{grid, false}, std::pair{zip, true}}) {
    if (axes_of.is_none()) continue;
    for (const auto& [key, values] : axes_of.cast<py::dict>()) {
      scenes::SweepAxis a{py::str(key).cast<std::string>(), {}, zipped};
      for (const auto& v : values.cast<py::sequence>()) a.values.push_back(set_value(v));
      axes.push_back(std::move(a));
    }
  }
  return axes;
}

py::list sweep(const std::string& scene, const py::object& grid, const py::object& zip,
               const py::object& sets, const py::object& steps, int repeat, const py::object& out) {
  if (repeat < 1)
    throw std::invalid_argument("repeat = " + std::to_string(repeat) + ": must be >= 1");
  const std::vector<scenes::SweepPoint> points = scenes::expand(sweep_axes(grid, zip), repeat);
  std::vector<std::string> fixed = assignments(sets);
  fixed.push_back("render=false");
  const int n = steps.is_none() ? 0 : steps.cast<int>();
  OutDir dir(out);
  fs::create_directories(dir.path / "runs");
  py::list results;
  for (const auto& p : points) {
    std::vector<std::string> s = fixed;
    for (const auto& a : p.assignments()) s.push_back(a);
    scenes::Json summary;
    {
      py::gil_scoped_release release;
      summary = run_into(scene, s, n, scenes::point_dir(dir.path, p.index));
    }
    py::dict row;
    row["index"] = p.index;
    py::dict values;
    for (const auto& [k, v] : p.values) values[py::str(k)] = v;
    row["values"] = values;
    row["seed"] = p.seed;
    row["summary"] = to_python(summary);
    results.append(row);
  }
  return results;
}

}  // namespace

void bind_scenes(py::module_& m) {
  m.def("scenes", &scene_names, "The built-in scenes' names, in `conform scenes` order.");
  m.def("scene_json", &scene_json, py::arg("name"),
        "The JSON file of a built-in scene (`conform scenes --show NAME`).");
  m.def("run", &run, py::arg("scene"), py::arg("out") = py::none(), py::arg("set") = py::none(),
        py::arg("steps") = py::none(), py::arg("render") = py::none(),
        "Runs a scene (built-in name or JSON file) as `conform run` does and returns its "
        "summary.json as a dict. out: the results folder (None: a temporary one, removed); "
        "set: {key: value} overrides (--set; a value that is not a str is given as JSON); "
        "steps: --steps; render=False: --no-render. Raises SceneError for a bad key or value.");
  m.def("sweep", &sweep, py::arg("scene"), py::arg("grid") = py::none(),
        py::arg("zip") = py::none(), py::arg("set") = py::none(), py::arg("steps") = py::none(),
        py::arg("repeat") = 1, py::arg("out") = py::none(),
        "Runs the points of a sweep one after the other in this process (no pictures): grid "
        "{key: [values]} combined as a product, zip {key: [values]} advanced together, each "
        "point `repeat` times with seeds 1..repeat. Each point's results go to OUT/runs/NNNNN. "
        "Returns [{index, values, seed, summary}] in point order.");
}

}  // namespace conform::python
