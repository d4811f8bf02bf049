// A run's plots say what they show (render/plots.hpp): a quantity that does not exist yet is a
// blank field of metrics.csv and a gap in its line, not 0; the event that makes it is marked; a
// quantity that is 0 throughout is a sentence in summary.json, not a flat plot; lengths are in
// millimetres; and the two tracking errors of arm-track are told apart on a log scale.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// `conform run SCENE ARGS` into a folder of this test's own (ctest runs the tests of this file
// in parallel processes).
fs::path run(const std::string& scene, const std::string& args) {
  const std::string test = testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path out =
      fs::path(testing::TempDir()) / ("conform_plots_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string cmd = (fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform").string() + " run " +
                          scene + " --no-render " + args + " --out " + out.string() + " > " +
                          out.string() + ".log 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return out;
}

bool have_gnuplot() {
  return std::system("command -v gnuplot > /dev/null 2>&1") == 0;
}

std::string read(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), {}};
}

// metrics.csv as rows of fields (kept as text: a blank field is "").
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::stringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.emplace_back();  // a blank last field
  return out;
}

Table read_csv(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  Table t;
  std::getline(in, line);
  t.columns = fields(line);
  while (std::getline(in, line)) t.rows.push_back(fields(line));
  return t;
}

TEST(ScenePlots, TheHandPieceIsBlankBeforeTheCutWhichThePlotMarks) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed (scripts/deps.sh installs it)";
  const fs::path out = run("cut", "--steps 45");
  const Json summary = Json::parse(read(out / "summary.json"));
  const double cut_at = summary["settings"]["cut"]["at"];
  const Table t = read_csv(out / "metrics.csv");
  const std::size_t time = t.column("t"), hand = t.column("hand_offset_mean"),
                    all = t.column("offset_mean");
  int before = 0, after = 0;
  for (const auto& row : t.rows) {
    ASSERT_EQ(row.size(), t.columns.size());
    EXPECT_FALSE(row[all].empty());  // every node exists at every row
    if (std::stod(row[time]) < cut_at) {
      EXPECT_EQ(row[hand], "") << "t = " << row[time];
      ++before;
    } else if (std::stod(row[time]) > cut_at + 0.02) {  // measured from the step after it
      EXPECT_FALSE(row[hand].empty()) << "t = " << row[time];
      EXPECT_GT(std::stod(row[hand]), 0.0);
      ++after;
    }
  }
  EXPECT_GT(before, 20);
  EXPECT_GT(after, 5);
  const std::string gp = read(out / "offsets.gp");
  std::ostringstream arrow;
  arrow << "set arrow from " << cut_at << ", graph 0";
  EXPECT_NE(gp.find(arrow.str()), std::string::npos) << gp;
  EXPECT_NE(gp.find("column('hand_offset_mean')*1000"), std::string::npos) << gp;
  EXPECT_NE(gp.find("[mm]"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "offsets.png"));
}

// On the default character (Debian's huesitos.fbx) the seams never open: its seam_gap plot
// would be a flat 0.
TEST(ScenePlots, AQuantityThatIsZeroThroughoutIsASentenceNotAPlot) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed (scripts/deps.sh installs it)";
  const fs::path out = run("character", "--steps 80");
  const Table t = read_csv(out / "metrics.csv");
  const std::size_t gap = t.column("seam_gap_rel");
  for (const auto& row : t.rows) ASSERT_EQ(std::stod(row[gap]), 0.0);
  const Json summary = Json::parse(read(out / "summary.json"));
  EXPECT_EQ(summary["plots"]["seam_gap"],
            "not drawn: seam_gap_rel is 0 at every row of metrics.csv");
  const Json& notes = summary["plot_notes"];
  EXPECT_NE(std::find(notes.begin(), notes.end(),
                      "seam_gap.png: seam_gap_rel is 0 at every row of metrics.csv"),
            notes.end())
      << notes;
  EXPECT_FALSE(fs::exists(out / "seam_gap.png"));
  EXPECT_TRUE(summary["failures"].empty());  // a note, not a failure
  EXPECT_TRUE(fs::exists(out / "secondary_motion.png"));
}

// The comparison the tear scenes exist for: the final physical and geometric profiles on one
// axis in mm, titled with their ratio; the opening over time marks the stroke's start and end
// (where the geometric opening steps up).
TEST(ScenePlots, FinalProfilesOverlaidWithTheirRatioAndTheStrokeMarked) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed (scripts/deps.sh installs it)";
  const fs::path out = run("character", "--steps 90");
  const Json summary = Json::parse(read(out / "summary.json"));
  const Json& tear = summary["settings"]["tear"];
  const double at = tear["at"], end = at + double(tear["duration"]);
  const std::string overlay = read(out / "final_profiles.gp");
  EXPECT_NE(overlay.find("'gap width [mm]'"), std::string::npos) << overlay;
  const Table profiles = read_csv(out / "profiles.csv");
  const std::string physics = profiles.columns[profiles.columns.size() / 2];
  const std::string geometric = profiles.columns.back();
  EXPECT_EQ(physics.rfind("physics_", 0), 0u) << physics;
  EXPECT_NE(overlay.find("column('" + physics + "')*1000"), std::string::npos) << overlay;
  EXPECT_NE(overlay.find("column('" + geometric + "')*1000"), std::string::npos) << overlay;
  // The ratio in the title is that of the largest widths of the two final columns.
  double p_max = 0, g_max = 0;
  for (const auto& row : profiles.rows) {
    p_max = std::max(p_max, std::stod(row[profiles.column(physics)]));
    g_max = std::max(g_max, std::stod(row[profiles.column(geometric)]));
  }
  ASSERT_GT(g_max, 0.0);
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "ratio %.2f)", p_max / g_max);
  EXPECT_NE(overlay.find(ratio), std::string::npos) << overlay;
  const std::string opening = read(out / "opening.gp");
  for (const double x : {at, end}) {
    std::ostringstream arrow;
    arrow << "set arrow from " << x << ", graph 0";
    EXPECT_NE(opening.find(arrow.str()), std::string::npos) << opening;
  }
  EXPECT_TRUE(fs::exists(out / "final_profiles.png"));
}

TEST(ScenePlots, ArmTrackErrorsAreOnALogScaleInMillimetres) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed (scripts/deps.sh installs it)";
  const fs::path out = run("arm-track", "--steps 30");
  const std::string gp = read(out / "tracking_error.gp");
  EXPECT_NE(gp.find("set logscale y"), std::string::npos) << gp;
  EXPECT_NE(gp.find("column('error_no_compensation')*1000"), std::string::npos) << gp;
  EXPECT_NE(gp.find("noenhanced"), std::string::npos);  // titles are plain text
  EXPECT_TRUE(fs::exists(out / "tracking_error.png"));
}

}  // namespace
