// Weights that do not sum to 1 (a real Blender export, FBX/animation_with_skeleton.fbx: sums
// 0.94–1.38) load by default with exactly one warning, and are refused with --strict-weights
// (scene files: model.strict_weights), from every command that loads a model: info, skin,
// cut, tear, drill and run. Runs the `conform` command (skipped when it is not built).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"

namespace fs = std::filesystem;
using namespace conform;

namespace {

const fs::path kConform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
const std::string kFbx = std::string(CONFORM_ASSIMP_MODELS) + "/FBX/animation_with_skeleton.fbx";

struct Result {
  int rc = -1;
  std::string out;  // stdout and stderr
};

Result conform_cli(const std::string& args) {
  Result r;
  FILE* p = popen((kConform.string() + " " + args + " 2>&1").c_str(), "r");
  char buf[1024];
  while (p && std::fgets(buf, sizeof buf, p)) r.out += buf;
  const int status = p ? pclose(p) : -1;
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The arguments of each command on the model, aimed from its bind pose: a plane through the
// middle, a scalpel and a drill across the largest face along its normal.
std::vector<std::pair<std::string, std::string>> commands(const fs::path& dir) {
  const io::SkinnedModel model = io::import_model(kFbx);
  const auto& m = model.mesh;
  const Eigen::Vector3d lo = m.current.rowwise().minCoeff(), hi = m.current.rowwise().maxCoeff();
  const double diag = (hi - lo).norm();
  std::int32_t best = 0;
  double area = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const auto& t = m.faces[static_cast<std::size_t>(f)];
    const double a = (m.current.col(t[1]) - m.current.col(t[0]))
                         .cross(m.current.col(t[2]) - m.current.col(t[0]))
                         .norm();
    if (a > area) area = a, best = f;
  }
  const auto& t = m.faces[static_cast<std::size_t>(best)];
  const Eigen::Vector3d p0 = m.current.col(t[0]), p1 = m.current.col(t[1]),
                        p2 = m.current.col(t[2]);
  const Eigen::Vector3d c = (p0 + p1 + p2) / 3, n = (p1 - p0).cross(p2 - p0).normalized(),
                        u = (p1 - p0).normalized();
  const double edge = std::min({(p1 - p0).norm(), (p2 - p1).norm(), (p0 - p2).norm()});
  const auto point = [](const Eigen::Vector3d& x) {
    return std::to_string(x.x()) + " " + std::to_string(x.y()) + " " + std::to_string(x.z());
  };
  const fs::path csv = dir / "scalpel.csv";
  {
    std::ofstream os(csv);
    os << "t,ax,ay,az,bx,by,bz\n";
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d at = c + (k - 1.5) * 0.1 * edge * u, a = at + 0.05 * diag * n,
                            b = at - 0.05 * diag * n;
      os << k << "," << a.x() << "," << a.y() << "," << a.z() << "," << b.x() << "," << b.y() << ","
         << b.z() << "\n";
    }
  }
  const std::string out = " --out " + (dir / "out").string();
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  return {
      {"info", "info " + kFbx},
      {"skin", "skin " + kFbx + " --time 0.4 --out " + (dir / "posed.obj").string()},
      {"cut", "cut " + kFbx + " --plane 1 0 0 " + std::to_string(mid.x()) + out},
      {"tear", "tear " + kFbx + " --scalpel " + csv.string() + out},
      {"drill", "drill " + kFbx + " --tip " + point(c + 0.05 * diag * n) + " --base " +
                    point(c - 0.05 * diag * n) + " --radius " + std::to_string(0.2 * edge) + out},
      // Two steps: the edits, due later, are off (an edit after the last step is refused).
      {"run",
       "run character --steps 2 --set cut.enabled=false --set tear.enabled=false "
       "--set drill.enabled=false --set model.file=" +
           kFbx + out},
  };
}

TEST(StrictWeightsCli, EveryCommandNormalizesByDefaultAndRefusesWhenStrict) {
  if (!fs::exists(kConform)) GTEST_SKIP() << "conform not built";
  const fs::path dir = fs::temp_directory_path() / ("conform_strict_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& [name, args] : commands(dir)) {
    const Result normal = conform_cli(args);
    EXPECT_EQ(normal.rc, 0) << name << ": " << normal.out;
    EXPECT_EQ(count(normal.out, "do not sum to 1"), 1) << name << ": " << normal.out;
    const std::string strict_args =
        name == "run" ? args + " --set model.strict_weights=true" : args + " --strict-weights";
    const Result strict = conform_cli(strict_args);
    EXPECT_NE(strict.rc, 0) << name << ": " << strict.out;
    EXPECT_NE(strict.out.find("sum to"), std::string::npos) << name << ": " << strict.out;
    EXPECT_NE(strict.out.find("strict weights"), std::string::npos) << name << ": " << strict.out;
  }
  fs::remove_all(dir);
}

}  // namespace
