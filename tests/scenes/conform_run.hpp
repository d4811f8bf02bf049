// Tests that run the `conform` command itself: one run into a fresh folder under the test
// temporary directory, its exit code, log and summary.json.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

namespace conform::test {

struct CommandRun {
  int rc = -1;
  std::string log;
  nlohmann::json summary;  // null when the run wrote none
  std::filesystem::path dir;
};

/// `conform run SCENE --out TMP/conform_TAG ARGS`, its output in TMP/conform_TAG.log.
inline CommandRun run_conform_scene(const std::string& scene, const std::string& args,
                                    const std::string& tag) {
  namespace fs = std::filesystem;
  const fs::path conform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
  CommandRun r;
  if (!fs::exists(conform)) {
    ADD_FAILURE() << "build the conform command first: " << conform;
    return r;
  }
  r.dir = fs::path(testing::TempDir()) / ("conform_" + tag);
  fs::remove_all(r.dir);
  const std::string cmd = conform.string() + " run " + scene + " --out " + r.dir.string() + " " +
                          args + " > " + r.dir.string() + ".log 2>&1";
  const int status = std::system(cmd.c_str());
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream log(r.dir.string() + ".log");
  r.log.assign(std::istreambuf_iterator<char>(log), {});
  std::ifstream in(r.dir / "summary.json");
  if (in) r.summary = nlohmann::json::parse(in, nullptr, false);
  return r;
}

}  // namespace conform::test
