#include "render/vtk_series.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "base/child_process.hpp"
#include "base/interrupt.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

// vtk_series.py's exit status when meshio is not installed; a program exec cannot start, 127.
constexpr int kMeshioMissing = 3;
constexpr int kCannotRun = 127;

// Appends " %.17g": a double written in text and read back exactly.
void add(std::string& out, double value) {
  char buf[40];
  const int n = std::snprintf(buf, sizeof buf, " %.17g", value);
  out.append(buf, static_cast<std::size_t>(n));
}

// The vertex properties of a frame, in file order: name and the value of vertex v.
struct Column {
  std::string name;
  const double* data;  // column-major 3 x #V or 2 x #V, or a plain vector
  int stride, offset;
};

std::vector<Column> columns_of(const VertexFields& f) {
  std::vector<Column> c;
  for (int k = 0; k < 3; ++k) c.push_back({std::string(1, "xyz"[k]), f.positions.data(), 3, k});
  for (int k = 0; k < 3; ++k)
    c.push_back({std::string("displacement_") + "xyz"[k], f.displacement.data(), 3, k});
  for (int k = 0; k < 3; ++k)
    c.push_back({std::string("velocity_") + "xyz"[k], f.velocity.data(), 3, k});
  c.push_back({"stretch", f.stretch.data(), 1, 0});
  if (!f.gap.empty()) c.push_back({"gap", f.gap.data(), 1, 0});
  for (int k = 0; k < 2 && f.principal_stress.cols() > 0; ++k)
    c.push_back({"principal_stress_" + std::to_string(k + 1), f.principal_stress.data(), 2, k});
  return c;
}

void check_sizes(const VertexFields& f) {
  const auto n = static_cast<std::size_t>(f.positions.cols());
  const bool ok = std::size_t(f.displacement.cols()) == n && std::size_t(f.velocity.cols()) == n &&
                  f.stretch.size() == n && f.piece.size() == n && f.tags.size() == f.faces.size() &&
                  (f.gap.empty() || f.gap.size() == n) &&
                  (f.principal_stress.cols() == 0 || std::size_t(f.principal_stress.cols()) == n);
  if (!ok) throw std::logic_error("VtkSeries: a vertex field's size is not the vertex count");
}

// A PLY that meshio reads back: the fields as double vertex properties, the piece as an int,
// the tags as the face properties the PLY frames use (surface, op, edit). In
// text: meshio 7's binary PLY reader takes one value of each face property for all faces.
std::string staging_ply(const VertexFields& f) {
  check_sizes(f);
  const std::vector<Column> columns = columns_of(f);
  std::string out = "ply\nformat ascii 1.0\ncomment conform vtk staging\n";
  out += "element vertex " + std::to_string(f.positions.cols()) + "\n";
  for (const Column& c : columns) out += "property double " + c.name + "\n";
  out += "property int piece\n";
  out += "element face " + std::to_string(f.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\n";
  out += "property uchar surface\nproperty uint op\nproperty uchar edit\nend_header\n";
  for (Eigen::Index v = 0; v < f.positions.cols(); ++v) {
    for (const Column& c : columns) add(out, c.data[c.stride * v + c.offset]);
    out.append(" ").append(std::to_string(f.piece[std::size_t(v)])).append("\n");
  }
  for (std::size_t i = 0; i < f.faces.size(); ++i) {
    out += "3";
    for (const auto v : f.faces[i]) out.append(" ").append(std::to_string(v));
    out.append(" ").append(std::to_string(int(f.tags[i].kind)));
    out.append(" ").append(std::to_string(f.tags[i].op));
    out.append(" ").append(std::to_string(int(f.tags[i].edit))).append("\n");
  }
  return out;
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

void say(Json& report, const char* list, const char* level, const std::string& message) {
  std::cerr << "conform run: " << level << ": " << message << "\n";
  report[list].push_back(message);
}

}  // namespace

VtkSeries::VtkSeries(fs::path run_dir) : dir_(std::move(run_dir)), staging_(dir_ / ".vtk-staging") {
  std::error_code ec;
  fs::create_directories(staging_, ec);
  if (ec) throw std::runtime_error("cannot create " + staging_.string() + ": " + ec.message());
}

VtkSeries::~VtkSeries() {
  std::error_code ec;  // a run that stopped early leaves no staging behind
  fs::remove_all(staging_, ec);
}

void VtkSeries::add(const std::string& name, int step, double time, const VertexFields& fields) {
  if (name_.empty()) {
    name_ = name;
    has_gap_ = !fields.gap.empty();
    has_stress_ = fields.principal_stress.cols() > 0;
    omitted_ = fields.omitted;
  }
  if (name != name_)
    throw std::logic_error("VtkSeries: frames of '" + name + "' in the series of '" + name_ + "'");
  if (has_gap_ != !fields.gap.empty() || has_stress_ != (fields.principal_stress.cols() > 0))
    throw std::logic_error("VtkSeries: the frames' fields changed within the run");
  char stem[32];
  std::snprintf(stem, sizeof stem, "frame_%06d", step);
  const Frame frame{step, time, std::string(stem) + ".ply", std::string(stem) + ".vtu"};
  write_file(staging_ / frame.ply, staging_ply(fields));
  frames_.push_back(frame);
}

Json VtkSeries::manifest() const {
  Json m;
  m["frames"] = Json::array();
  for (const Frame& f : frames_)
    m["frames"].push_back({{"file", f.ply}, {"vtu", f.vtu}, {"time", f.time}, {"step", f.step}});
  const auto vector = [](const std::string& name, const std::string& suffixes) {
    Json properties = Json::array();
    for (const char s : suffixes) properties.push_back(name + "_" + s);
    return Json{{"name", name}, {"properties", properties}};
  };
  const auto scalar = [](const std::string& name) {
    return Json{{"name", name}, {"properties", Json::array({name})}};
  };
  m["point_data"] =
      Json::array({vector("displacement", "xyz"), vector("velocity", "xyz"), scalar("stretch")});
  if (has_gap_) m["point_data"].push_back(scalar("gap"));
  if (has_stress_) m["point_data"].push_back(vector("principal_stress", "12"));
  m["point_data"].push_back(scalar("piece"));
  // The PLY frames' face properties, under names that say what they are.
  m["cell_data"] = Json::array();
  for (const auto& [name, property] : {std::pair{"face_tag", "surface"}, std::pair{"face_op", "op"},
                                       std::pair{"face_edit", "edit"}})
    m["cell_data"].push_back(Json{{"name", name}, {"property", property}});
  return m;
}

Json VtkSeries::finish() {
  Json report = {{"frames_of", name_}, {"warnings", Json::array()}, {"failures", Json::array()}};
  const Json m = manifest();
  report["point_data"] = Json::array();
  for (const Json& f : m["point_data"]) report["point_data"].push_back(f["name"]);
  report["cell_data"] = Json::array();
  for (const Json& f : m["cell_data"]) report["cell_data"].push_back(f["name"]);
  report["omitted"] = omitted_;
  write_file(staging_ / "manifest.json", m.dump(1) + "\n");
  write_file(staging_ / "vtk_series.py", vtk_series_script());
  const fs::path tmp = dir_ / ".vtk-tmp", log = dir_ / "vtk.log", out = dir_ / "vtk";
  fs::remove_all(tmp);
  ChildOptions options;
  options.log = fs::absolute(log).string();
  ChildProcess python({kVtkPython, fs::absolute(staging_ / "vtk_series.py").string(),
                       fs::absolute(staging_).string(), fs::absolute(tmp).string()},
                      options);
  const int status = python.running() ? python.wait() : -1;
  check_interrupt();
  fs::remove_all(staging_);
  if (status != 0) {
    fs::remove_all(tmp);  // nothing half-written
    if (status == kCannotRun)
      say(report, "warnings", "warning",
          std::string(kVtkPython) +
              " cannot be run (scripts/deps.sh installs python3-meshio): no "
              "ParaView series (vtk/)");
    else if (status == kMeshioMissing)
      say(report, "warnings", "warning",
          "meshio is not installed for " + std::string(kVtkPython) +
              " (scripts/deps.sh installs python3-meshio): no ParaView series (vtk/)");
    else
      say(report, "failures", "error",
          "the ParaView series (vtk/) was not written: " + std::string(kVtkPython) +
              " vtk_series.py exited with status " + std::to_string(status) + " (see vtk.log)");
    return report;
  }
  fs::remove(log);
  fs::remove_all(out);
  fs::rename(tmp, out);
  report["pvd"] = "vtk/series.pvd";
  report["files"] = Json::array();
  for (const Frame& f : frames_) report["files"].push_back("vtk/" + f.vtu);
  return report;
}

}  // namespace conform::scenes
