// The ParaView series (outputs.vtk, conform run --vtk; scenes/render/vtk_series.hpp) through
// the `conform` command: its .pvd and .vtu files read back with meshio by
// tests/scenes/vtk_series_check.py against the run's PLY frames, metrics.csv and summary.json;
// a missing or failing meshio is said, and leaves no partial series; a bad key is refused.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "conform_run.hpp"

namespace {

namespace fs = std::filesystem;
using conform::test::run_conform_scene;

constexpr const char* kPython = "/usr/bin/python3";

bool have_meshio() {
  const std::string cmd = std::string(kPython) + " -c 'import meshio' > /dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

// Runs tests/scenes/vtk_series_check.py on a run folder; its report goes to the test's output.
int check_series(const fs::path& run, const std::string& options) {
  const std::string cmd = std::string(kPython) + " " + CONFORM_SOURCE_DIR +
                          "/tests/scenes/vtk_series_check.py " + run.string() + " " + options;
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A short run of each scene: no pictures or plots, only the frames and the series.
const std::string kQuiet = "--no-render --set outputs.plots=false --vtk";

// A tear made early and short, with a frame every 10 steps (0, 10, 20, 30).
const std::string kShortTear =
    "--steps 30 --set tear.at=0.1 --set tear.duration=0.2 --set outputs.frames_every=10 " + kQuiet;

void expect_no_leftovers(const fs::path& run) {
  EXPECT_FALSE(fs::exists(run / ".vtk-staging"));
  EXPECT_FALSE(fs::exists(run / ".vtk-tmp"));
}

TEST(VtkSeries, TearOpeningReadsBackWithTheRunsFramesAndFields) {
  if (!have_meshio()) GTEST_SKIP() << "meshio is not installed for " << kPython;
  const auto r = run_conform_scene("tear-opening", kShortTear, "vtk_tear");
  ASSERT_EQ(r.rc, 0) << r.log;
  ASSERT_TRUE(r.summary.contains("vtk")) << r.log;
  const auto& vtk = r.summary["vtk"];
  EXPECT_EQ(vtk["files"].size(), 4u);
  EXPECT_TRUE(vtk["omitted"].empty()) << vtk.dump();
  for (const char* field :
       {"displacement", "velocity", "stretch", "gap", "principal_stress", "piece"})
    EXPECT_NE(std::find(vtk["point_data"].begin(), vtk["point_data"].end(), field),
              vtk["point_data"].end())
        << field;
  expect_no_leftovers(r.dir);
  // The scene's isotropic pre-stress, 80.8 kPa: the unstrained first frame's principal stresses.
  EXPECT_EQ(check_series(r.dir, "--prestress 80800 --gap"), 0);
}

TEST(VtkSeries, CutSeriesHasBothPiecesAndSaysWhyItHasNoGap) {
  if (!have_meshio()) GTEST_SKIP() << "meshio is not installed for " << kPython;
  const auto r = run_conform_scene(
      "cut", "--steps 40 --set cut.at=0.2 --set outputs.frames_every=20 " + kQuiet, "vtk_cut");
  ASSERT_EQ(r.rc, 0) << r.log;
  ASSERT_TRUE(r.summary.contains("vtk")) << r.log;
  EXPECT_EQ(r.summary["metrics"]["pieces"], 2);
  ASSERT_EQ(r.summary["vtk"]["omitted"].size(), 1u);
  EXPECT_EQ(r.summary["vtk"]["omitted"][0].get<std::string>().rfind("gap:", 0), 0u);
  expect_no_leftovers(r.dir);
  EXPECT_EQ(check_series(r.dir, ""), 0);
}

// A module named meshio first on PYTHONPATH, for the run's python3 to import instead of meshio
// (restored when the test ends).
class FakeMeshio {
 public:
  FakeMeshio(const std::string& tag, const std::string& source) {
    dir_ = fs::path(testing::TempDir()) / ("conform_fake_meshio_" + tag);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "meshio.py") << source;
    if (const char* old = std::getenv("PYTHONPATH")) old_ = old;
    setenv("PYTHONPATH", dir_.c_str(), 1);
  }
  ~FakeMeshio() {
    if (old_)
      setenv("PYTHONPATH", old_->c_str(), 1);
    else
      unsetenv("PYTHONPATH");
  }

 private:
  fs::path dir_;
  std::optional<std::string> old_;
};

// meshio not installed: a warning on stderr and in summary.json, the run succeeds, no vtk/.
TEST(VtkSeries, MissingMeshioIsSaidAndLeavesNoSeries) {
  const FakeMeshio fake("missing", "raise ImportError('no meshio here (the test hides it)')\n");
  const auto r = run_conform_scene("tear-opening", kShortTear, "vtk_no_meshio");
  ASSERT_EQ(r.rc, 0) << r.log;
  EXPECT_NE(r.log.find("warning: meshio is not installed"), std::string::npos) << r.log;
  ASSERT_TRUE(r.summary.contains("vtk")) << r.log;
  ASSERT_EQ(r.summary["vtk"]["warnings"].size(), 1u);
  EXPECT_NE(r.summary["vtk"]["warnings"][0].get<std::string>().find("python3-meshio"),
            std::string::npos);
  EXPECT_FALSE(r.summary["vtk"].contains("pvd"));
  EXPECT_FALSE(fs::exists(r.dir / "vtk"));
  expect_no_leftovers(r.dir);
}

// meshio failing half-way (after writing one frame): a failure of the run (exit 1), and no vtk/ at
// all.
TEST(VtkSeries, FailingConversionIsAFailureAndLeavesNoPartialSeries) {
  const FakeMeshio fake(
      "failing",
      "class _Any(dict):\n"
      "    def __contains__(self, key): return True\n"
      "    def __getitem__(self, key): return [0.0]\n"
      "class _Cells:\n"
      "    type = 'triangle'\n"
      "class _Read:\n"
      "    points, cells, point_data, cell_data = [], [_Cells()], _Any(), _Any()\n"
      "class Mesh:\n"
      "    def __init__(self, *args, **kwargs): pass\n"
      "def read(path, file_format=None): return _Read()\n"
      "written = []\n"
      "def write(path, mesh, file_format=None):\n"
      "    if written: raise RuntimeError('disk full (the test says so)')\n"
      "    open(path, 'w').write('one frame')\n"
      "    written.append(path)\n");
  const auto r = run_conform_scene("tear-opening", kShortTear, "vtk_failing");
  EXPECT_EQ(r.rc, 1) << r.log;
  EXPECT_NE(r.log.find("error: the ParaView series (vtk/) was not written"), std::string::npos)
      << r.log;
  ASSERT_TRUE(r.summary.contains("vtk")) << r.log;
  EXPECT_EQ(r.summary["vtk"]["failures"].size(), 1u);
  EXPECT_EQ(r.summary["failures"].size(), 1u);
  EXPECT_FALSE(fs::exists(r.dir / "vtk"));
  EXPECT_TRUE(fs::exists(r.dir / "vtk.log"));
  expect_no_leftovers(r.dir);
}

TEST(VtkSeries, NonBooleanKeyIsRefusedNamingKeyAndValue) {
  const auto r = run_conform_scene("tear-opening", "--steps 2 --set outputs.vtk=3", "vtk_bad");
  EXPECT_NE(r.rc, 0);
  EXPECT_NE(r.log.find("outputs.vtk"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("3"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("must be true or false"), std::string::npos) << r.log;
  EXPECT_FALSE(fs::exists(r.dir / "vtk"));
}

TEST(VtkSeries, OffByDefault) {
  const auto r = run_conform_scene("tear-opening",
                                   "--steps 30 --set tear.at=0.1 --set tear.duration=0.2 "
                                   "--no-render --set outputs.plots=false",
                                   "vtk_default");
  ASSERT_EQ(r.rc, 0) << r.log;
  EXPECT_FALSE(r.summary.contains("vtk"));
  EXPECT_FALSE(fs::exists(r.dir / "vtk"));
}

}  // namespace
