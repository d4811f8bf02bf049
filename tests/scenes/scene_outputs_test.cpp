// A run's output folder is written atomically (scenes/base/output_folder.hpp): a failed run leaves
// the earlier results untouched, a reused folder holds only the new run's files, and a run into
// a folder that another run is writing is refused. Through the `conform` command.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Result {
  int rc = -1;
  std::string log;
};

Result conform_run(const std::string& args, const fs::path& out) {
  const fs::path conform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
  const fs::path log = out.string() + ".log";
  const std::string cmd = conform.string() + " run " + args + " --out " + out.string() +
                          " --set outputs.plots=false > " + log.string() + " 2>&1";
  Result r;
  const int status = std::system(cmd.c_str());
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  std::ifstream in(log);
  r.log.assign(std::istreambuf_iterator<char>(in), {});
  return r;
}

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Nothing but `target` (and the logs of this test) beside it: no staging folder, and no lock
// (a run removes its lock file when it ends).
void expect_no_staging(const fs::path& target) {
  for (const auto& e : fs::directory_iterator(target.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".staging-"), std::string::npos) << e.path();
  EXPECT_FALSE(fs::exists(target.parent_path() / ("." + target.filename().string() + ".lock")));
}

fs::path fresh(const std::string& tag) {
  const fs::path root = fs::path(testing::TempDir()) / ("conform_outputs_" + tag);
  fs::remove_all(root);
  fs::create_directories(root);
  return root / "out";
}

const std::string kShortRun = "arm-track --steps 20";

TEST(SceneOutputs, FailedRunLeavesEarlierResultsUntouched) {
  const fs::path out = fresh("failed");
  ASSERT_EQ(conform_run(kShortRun, out).rc, 0);
  const std::string summary = read(out / "summary.json"), metrics = read(out / "metrics.csv");
  ASSERT_FALSE(summary.empty());
  // Fails inside the run (the model is parsed by the scene, read by the run): a corrupt file.
  const Result r = conform_run(
      "character --steps 5 --set cut.enabled=false --set tear.enabled=false "
      "--set drill.enabled=false --set model.file=" +
          std::string(CONFORM_TEST_DATA) + "/broken/triangle_vertex_out_of_range.x",
      out);
  EXPECT_NE(r.rc, 0) << r.log;
  EXPECT_LT(r.rc, 128) << r.log;
  EXPECT_NE(r.log.find("triangle_vertex_out_of_range.x"), std::string::npos) << r.log;
  EXPECT_EQ(read(out / "summary.json"), summary);
  EXPECT_EQ(read(out / "metrics.csv"), metrics);
  expect_no_staging(out);
}

TEST(SceneOutputs, ReusedFolderHoldsOnlyTheNewRun) {
  const fs::path out = fresh("reused");
  ASSERT_EQ(conform_run(kShortRun, out).rc, 0);
  EXPECT_TRUE(fs::exists(out / ".conform-run"));  // an earlier result: the next run replaces it
  std::ofstream(out / "frames" / "stale_000001.ply") << "ply\n";
  std::ofstream(out / "stale.csv") << "x\n1\n";
  ASSERT_EQ(conform_run(kShortRun, out).rc, 0);
  EXPECT_FALSE(fs::exists(out / "frames" / "stale_000001.ply"));
  EXPECT_FALSE(fs::exists(out / "stale.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  expect_no_staging(out);
}

// A folder of other files is the user's: refused with exit 2, every file kept.
TEST(SceneOutputs, FolderOfOtherFilesIsRefused) {
  const fs::path out = fresh("foreign");
  fs::create_directories(out);
  std::ofstream(out / "thesis.tex") << "mine\n";
  const Result r = conform_run(kShortRun, out);
  EXPECT_EQ(r.rc, 2) << r.log;
  EXPECT_NE(r.log.find("not an earlier Conform result"), std::string::npos) << r.log;
  EXPECT_EQ(read(out / "thesis.tex"), "mine\n");
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_FALSE(fs::exists(out.parent_path() / ".out.lock"));
  expect_no_staging(out);
}

// A run holds an exclusive flock on .NAME.lock while it writes; here the test holds it, as a
// concurrent run would, so the refusal is deterministic.
TEST(SceneOutputs, BusyFolderIsRefused) {
  const fs::path out = fresh("busy");
  ASSERT_EQ(conform_run(kShortRun, out).rc, 0);
  const std::string summary = read(out / "summary.json");
  const fs::path lock = out.parent_path() / ".out.lock";
  const int fd = open(lock.c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  const Result r = conform_run(kShortRun, out);
  close(fd);
  EXPECT_NE(r.rc, 0) << r.log;
  EXPECT_NE(r.log.find("another run is writing it"), std::string::npos) << r.log;
  EXPECT_EQ(read(out / "summary.json"), summary);
  // Released: the next run goes through.
  EXPECT_EQ(conform_run(kShortRun, out).rc, 0);
  expect_no_staging(out);
}

}  // namespace
