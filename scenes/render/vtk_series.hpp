// The ParaView time series of a run (`outputs.vtk`): each kept frame's vertex fields
// (vertex_fields.hpp) as vtk/frame_STEP.vtu and one vtk/series.pvd that indexes them by time.
//
// conform writes each frame to a staging PLY (the fields as vertex properties, the tags as face
// properties) while the run goes; finish() then runs vtk_series.py (shipped inside conform) with
// Debian's /usr/bin/python3, which writes the .vtu files with meshio and the .pvd with
// ElementTree, the way the plots run gnuplot: a child process (child_process.hpp), its output in
// vtk.log. The series is written into a temporary folder and renamed to vtk/ only when complete;
// the staging files are removed either way.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "base/scene_config.hpp"
#include "render/vertex_fields.hpp"

namespace conform::scenes {

class VtkSeries {
 public:
  /// Stages frames under `run_dir`/.vtk-staging (created now; throws std::runtime_error when it
  /// cannot be).
  explicit VtkSeries(std::filesystem::path run_dir);
  ~VtkSeries();
  VtkSeries(const VtkSeries&) = delete;
  VtkSeries& operator=(const VtkSeries&) = delete;

  /// Stages one frame of the body whose PLY frames are named `name` (the first name given is
  /// the series'; a frame of another name is refused with std::logic_error).
  void add(const std::string& name, int step, double time, const VertexFields& fields);
  std::size_t size() const { return frames_.size(); }

  /// Writes vtk/ and returns summary.json's "vtk": the .pvd, the .vtu files, the fields and what
  /// was left out; "warnings" (python3 or meshio missing: no series, the run goes on) and
  /// "failures" (the conversion failed: the run exits 1), each also said on stderr.
  Json finish();

 private:
  struct Frame {
    int step;
    double time;
    std::string ply, vtu;
  };
  Json manifest() const;

  std::filesystem::path dir_, staging_;
  std::string name_;
  bool has_gap_ = false, has_stress_ = false;
  std::vector<std::string> omitted_;
  std::vector<Frame> frames_;
};

/// The interpreter the series is written with: Debian's, where python3-meshio installs meshio.
inline constexpr const char* kVtkPython = "/usr/bin/python3";

/// The text of vtk_series.py (scenes/render), built into conform (vtk_series_script.cpp.in).
const char* vtk_series_script();

}  // namespace conform::scenes
