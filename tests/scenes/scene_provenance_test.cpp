// Every summary.json says where its results come from (scenes/kinds/provenance.hpp): the commit
// and build, the libraries' versions, the exact command line, the host and the start time. Each
// field is checked against an independent source: git itself, the libraries' own headers and
// functions, gethostname and the clock around the run.
#include <LinearMath/btScalar.h>
#include <assimp/version.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

fs::path conform_binary() {
  return fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
}

// The output of a shell command (its first line), or "" when it fails.
std::string first_line_of(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return "";
  char line[512] = {};
  const bool got = std::fgets(line, sizeof line, pipe) != nullptr;
  const int status = ::pclose(pipe);
  if (!got || status != 0) return "";
  std::string s = line;
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

// The commit git reports for the source tree, or "unknown" when the tree is not a checkout of
// its own (what the build records then).
std::string expected_commit() {
  const std::string src = CONFORM_SOURCE_DIR;
  const std::string top =
      first_line_of("git -C '" + src + "' rev-parse --show-toplevel 2>/dev/null");
  if (top.empty() || fs::weakly_canonical(top) != fs::weakly_canonical(src)) return "unknown";
  return first_line_of("git -C '" + src + "' rev-parse HEAD");
}

Json read_json(const fs::path& file) {
  std::ifstream in(file);
  return Json::parse(in);
}

// Seconds since the epoch of an ISO 8601 UTC time "YYYY-MM-DDTHH:MM:SS.mmmZ".
double epoch_seconds(const std::string& iso) {
  std::tm t{};
  int ms = 0;
  EXPECT_EQ(std::sscanf(iso.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &t.tm_year, &t.tm_mon, &t.tm_mday,
                        &t.tm_hour, &t.tm_min, &t.tm_sec, &ms),
            7)
      << iso;
  t.tm_year -= 1900;
  t.tm_mon -= 1;
  return double(::timegm(&t)) + ms / 1000.0;
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

void expect_build_and_libraries(const Json& p) {
  EXPECT_EQ(p.at("git_commit"), expected_commit());
  EXPECT_TRUE(p.at("git_dirty").is_boolean());
  EXPECT_FALSE(p.at("build_type").get<std::string>().empty());
  EXPECT_FALSE(p.at("compiler").get<std::string>().empty());
  EXPECT_EQ(p.at("bullet_version"), std::to_string(BT_BULLET_VERSION / 100) + "." +
                                        std::to_string(BT_BULLET_VERSION % 100));
  EXPECT_EQ(p.at("assimp_version"), std::to_string(aiGetVersionMajor()) + "." +
                                        std::to_string(aiGetVersionMinor()) + "." +
                                        std::to_string(aiGetVersionPatch()));
  EXPECT_EQ(p.at("bullet_precision"), sizeof(btScalar) == 8 ? "double" : "float");
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(p.at("host"), std::string(host));
}

TEST(SceneProvenance, ASceneSummaryNamesItsBuildCommandHostAndStart) {
  const fs::path out = fs::path(testing::TempDir()) / "conform_provenance_scene";
  fs::remove_all(out);
  const std::vector<std::string> args = {
      conform_binary().string(), "run",   "arm-track", "--steps", "3", "--set",
      "outputs.plots=false",     "--out", out.string()};
  std::string command;
  for (const std::string& a : args) command += "'" + a + "' ";
  const double before = now_seconds();
  ASSERT_EQ(std::system((command + "> /dev/null 2>&1").c_str()), 0) << command;
  const double after = now_seconds();

  const Json p = read_json(out / "summary.json").at("provenance");
  expect_build_and_libraries(p);
  EXPECT_EQ(p.at("command_line").get<std::vector<std::string>>(), args);
  EXPECT_EQ(p.at("working_directory"), fs::current_path().string());
  const double started = epoch_seconds(p.at("started_at"));
  EXPECT_GE(started, before - 1.0);  // milliseconds are truncated
  EXPECT_LE(started, after);
  fs::remove_all(out);
}

// The mesh commands (cut, tear, drill of a model file) write the same block.
TEST(SceneProvenance, AMeshCommandSummaryNamesItsBuildAndCommand) {
  const fs::path out = fs::path(testing::TempDir()) / "conform_provenance_mesh";
  fs::remove_all(out);
  const std::vector<std::string> args = {conform_binary().string(),
                                         "drill",
                                         "arm",
                                         "--tip",
                                         "0",
                                         "-0.2",
                                         "0.4",
                                         "--base",
                                         "0",
                                         "0.2",
                                         "0.4",
                                         "--radius",
                                         "0.01",
                                         "--out",
                                         out.string()};
  std::string command;
  for (const std::string& a : args) command += "'" + a + "' ";
  ASSERT_EQ(std::system((command + "> /dev/null 2>&1").c_str()), 0) << command;
  const Json p = read_json(out / "summary.json").at("provenance");
  expect_build_and_libraries(p);
  EXPECT_EQ(p.at("command_line").get<std::vector<std::string>>(), args);
  fs::remove_all(out);
}

}  // namespace
