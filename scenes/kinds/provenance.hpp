// Where a run's results come from, for every summary.json: the build (commit, compiler, the
// libraries' versions, Bullet's precision), the exact command line, the host and the start time.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace conform::scenes {

/// The commit the scenes were built from (generated at build time by cmake/build_info.cmake).
struct BuildInfo {
  std::string git_commit;  ///< "unknown" when built outside the project's git checkout
  bool git_dirty = false;  ///< tracked files differed from the commit (or git could not tell)
  std::string build_type;  ///< CMake's build type, e.g. "Release"
};
BuildInfo build_info();

/// The process's command line as it was given (argv, from /proc/self/cmdline): the `conform`
/// command, or the Python interpreter and its script when the module runs a scene.
std::vector<std::string> command_line();

/// An ISO 8601 UTC time, e.g. "2026-12-06T08:01:02.345Z".
std::string utc_time(std::chrono::system_clock::time_point t);

/// The summary's "provenance" object for a run that started at `started`.
nlohmann::json provenance(std::chrono::system_clock::time_point started);

}  // namespace conform::scenes
