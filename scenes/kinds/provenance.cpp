#include "kinds/provenance.hpp"

#include <LinearMath/btScalar.h>
#include <assimp/version.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "conform/bullet/convert.hpp"
#include "conform/version.hpp"
#include "render/f3d_render.hpp"

namespace conform::scenes {

std::vector<std::string> command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string all{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::vector<std::string> args;
  for (std::size_t at = 0; at < all.size();) {  // NUL-terminated words
    const std::size_t end = std::min(all.find('\0', at), all.size());
    args.push_back(all.substr(at, end - at));
    at = end + 1;
  }
  return args;
}

std::string utc_time(std::chrono::system_clock::time_point t) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch());
  const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char buf[40];
  const std::size_t n = std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &utc);
  std::snprintf(buf + n, sizeof buf - n, ".%03dZ", int(ms.count() % 1000));
  return buf;
}

namespace {

std::string host_name() {
  char name[256] = {};
  return ::gethostname(name, sizeof name - 1) == 0 ? name : "unknown";
}

std::string compiler() {
#if defined(__clang__)
  return std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  return std::string("gcc ") + __VERSION__;
#else
  return "unknown";
#endif
}

// Bullet's version as its header states it (BT_BULLET_VERSION 325 is 3.25).
std::string bullet_version() {
  const int v = btGetVersion();
  return std::to_string(v / 100) + "." + std::to_string(v % 100);
}

// The assimp library this process runs with (asked at run time, not its header).
std::string assimp_version() {
  return std::to_string(aiGetVersionMajor()) + "." + std::to_string(aiGetVersionMinor()) + "." +
         std::to_string(aiGetVersionPatch());
}

std::string working_directory() {
  std::error_code ec;  // a folder removed under the run has no path
  const std::filesystem::path cwd = std::filesystem::current_path(ec);
  return ec ? "unknown" : cwd.string();
}

}  // namespace

nlohmann::json provenance(std::chrono::system_clock::time_point started) {
  const BuildInfo build = build_info();
  const std::vector<std::string> argv = command_line();
  return {{"conform_version", conform::version()},
          {"git_commit", build.git_commit},
          {"git_dirty", build.git_dirty},
          {"build_type", build.build_type},
          {"compiler", compiler()},
          {"bullet_version", bullet_version()},
          {"bullet_precision", bullet::bullet_precision()},
          {"assimp_version", assimp_version()},
          {"eigen_version", std::to_string(EIGEN_WORLD_VERSION) + "." +
                                std::to_string(EIGEN_MAJOR_VERSION) + "." +
                                std::to_string(EIGEN_MINOR_VERSION)},
          {"command_line", argv},
          {"command", shell_words(argv)},
          {"working_directory", working_directory()},
          {"host", host_name()},
          {"started_at", utc_time(started)}};
}

}  // namespace conform::scenes
