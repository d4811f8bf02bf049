#include "base/output_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "conform/version.hpp"

namespace conform::scenes {
namespace fs = std::filesystem;

namespace {

fs::path beside(const fs::path& target, const std::string& suffix) {
  return target.parent_path() / ("." + target.filename().string() + suffix);
}

[[noreturn]] void fail(const fs::path& dir, const std::string& why) {
  throw std::runtime_error("output folder " + dir.string() + ": " + why);
}

[[noreturn]] void refuse(const fs::path& dir, const std::string& why) {
  throw OutputRefused("output folder " + dir.string() + ": " + why + "; nothing written");
}

// Whether `path` is `folder` or lies somewhere under it (both absolute and normal).
bool within(const fs::path& path, const fs::path& folder) {
  const fs::path rel = path.lexically_relative(folder);
  return !rel.empty() && *rel.begin() != "..";
}

// The path with its symbolic links resolved, as far as it exists.
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(p, ec);
  return ec ? p : r;
}

bool empty_folder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_empty(dir, ec) && !ec;
}

// The folders the rules protect: the current folder (and so its ancestors) and the inputs.
void refuse_protected(const fs::path& target, const std::vector<fs::path>& inputs) {
  if (target == target.root_path()) refuse(target, "is the root folder");
  const fs::path real = resolved(target);
  std::error_code ec;
  const fs::path cwd = resolved(fs::current_path(ec));
  if (!ec && within(cwd, real))
    refuse(target, real == cwd ? "is the current folder, whose files the results would replace"
                               : "is an ancestor of the current folder (" + cwd.string() +
                                     "), which the results would replace");
  for (const auto& input : inputs) {
    if (input.empty() || !fs::exists(input, ec)) continue;
    if (within(resolved(fs::absolute(input, ec)), real))
      refuse(target, "holds the input " + input.string() + ", which the results would replace");
  }
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    refuse(target, "exists and is not a folder");
}

}  // namespace

namespace {

fs::path absolute_target(const fs::path& target) {
  if (target.empty()) refuse(target, "no folder given");
  std::error_code ec;
  fs::path t = fs::absolute(target, ec).lexically_normal();
  if (ec) refuse(target, "cannot make its absolute path: " + ec.message());
  if (t.filename().empty() && t != t.root_path()) t = t.parent_path();  // a trailing '/'
  return t;
}

void refuse_foreign(const fs::path& target) {
  std::error_code ec;
  if (fs::is_directory(target, ec) && !empty_folder(target) && !fs::exists(target / kRunMarker, ec))
    refuse(target, std::string("is not empty and is not an earlier Conform result (it has no ") +
                       kRunMarker + " marker): give a new or empty folder");
}

}  // namespace

void check_output_folder(const fs::path& target, const std::vector<fs::path>& inputs) {
  const fs::path t = absolute_target(target);
  refuse_protected(t, inputs);
  refuse_foreign(t);
}

OutputFolder::OutputFolder(fs::path target, const std::vector<fs::path>& inputs)
    : target_(absolute_target(target)) {
  std::error_code ec;
  refuse_protected(target_, inputs);
  fs::create_directories(target_.parent_path(), ec);
  if (ec) fail(target_, "cannot create its parent: " + ec.message());
  lock();
  try {
    refuse_foreign(target_);
    remove_stale_staging();
    make_staging();
  } catch (...) {
    if (!staging_.empty()) fs::remove_all(staging_, ec);
    unlock();
    throw;
  }
}

void OutputFolder::make_staging() {
  std::error_code ec;
  staging_ = beside(target_, ".staging-" + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  fs::create_directories(staging_, ec);
  if (ec) fail(target_, "cannot create " + staging_.string() + ": " + ec.message());
  std::ofstream marker(staging_ / kRunMarker);
  marker << "conform " << conform::version() << "\n";
  if (!marker) fail(target_, "cannot write " + (staging_ / kRunMarker).string());
}

// The lock file locked is the one on disk: a run that ends removes its lock file while still
// holding it, so a file locked after that is no one's and is opened anew.
void OutputFolder::lock() {
  lock_path_ = beside(target_, ".lock");
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      fail(target_, "cannot open the lock " + lock_path_.string() + ": " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      ::close(fd);
      if (error == EWOULDBLOCK)
        fail(target_,
             "another run is writing it (lock " + lock_path_.string() + "); nothing written");
      fail(target_, "cannot lock " + lock_path_.string() + ": " + std::strerror(error));
    }
    struct stat held {
    }, on_disk{};
    if (::fstat(fd, &held) == 0 && ::stat(lock_path_.c_str(), &on_disk) == 0 &&
        held.st_dev == on_disk.st_dev && held.st_ino == on_disk.st_ino) {
      lock_fd_ = fd;
      return;
    }
    ::close(fd);
  }
  fail(target_, "cannot lock " + lock_path_.string() + ": it keeps being replaced");
}

void OutputFolder::unlock() {
  if (lock_fd_ < 0) return;
  ::unlink(lock_path_.c_str());  // still locked: no one else holds this file now
  ::close(lock_fd_);
  lock_fd_ = -1;
}

// Staging folders of runs into this --out that were killed (SIGKILL, a node lost): with the
// lock held no run is writing here, and their process is gone. One whose pid is alive here (a
// run on another machine of a shared file system, say) is left alone.
void OutputFolder::remove_stale_staging() const {
  const std::string prefix = "." + target_.filename().string() + ".staging-";
  std::vector<fs::path> stale;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(target_.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid()) continue;  // replaced below
    if (pid > 0 && (::kill(pid, 0) == 0 || errno == EPERM)) continue;
    stale.push_back(e.path());
  }
  for (const auto& p : stale) fs::remove_all(p, ec);
}

OutputFolder::~OutputFolder() {
  std::error_code ec;
  if (!committed_ && !staging_.empty()) fs::remove_all(staging_, ec);
  unlock();
}

void OutputFolder::commit() {
  std::error_code ec;
  if (fs::exists(target_, ec)) {
    // Only an earlier result is replaced, even if files came into the folder during the run.
    if (!empty_folder(target_) && !fs::exists(target_ / kRunMarker, ec))
      fail(target_, std::string("is no longer an earlier Conform result (no ") + kRunMarker +
                        "): the new results were not put in its place");
    // One step: the earlier results and the new ones trade places, then the earlier go.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0)
      fail(target_, std::string("cannot swap the new results in: ") + std::strerror(errno));
    committed_ = true;
    fs::remove_all(staging_, ec);  // now the earlier results
    return;
  }
  fs::rename(staging_, target_, ec);
  if (ec) fail(target_, "cannot move the new results in: " + ec.message());
  committed_ = true;
}

}  // namespace conform::scenes
