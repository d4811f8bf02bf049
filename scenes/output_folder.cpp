#include "output_folder.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace conform::scenes {
namespace fs = std::filesystem;

namespace {

fs::path beside(const fs::path& target, const std::string& suffix) {
  return target.parent_path() / ("." + target.filename().string() + suffix);
}

[[noreturn]] void fail(const fs::path& dir, const std::string& why) {
  throw std::runtime_error("output folder " + dir.string() + ": " + why);
}

}  // namespace

OutputFolder::OutputFolder(fs::path target) : target_(std::move(target)) {
  if (target_.filename().empty() || target_.filename() == "." || target_.filename() == "..")
    target_ = fs::absolute(target_).lexically_normal();
  if (target_.filename().empty()) target_ = target_.parent_path();
  std::error_code ec;
  if (!target_.parent_path().empty()) fs::create_directories(target_.parent_path(), ec);
  if (ec) fail(target_, "cannot create its parent: " + ec.message());
  if (fs::exists(target_, ec) && !fs::is_directory(target_, ec))
    fail(target_, "exists and is not a folder");
  const fs::path lock = beside(target_, ".lock");
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0)
    fail(target_, "cannot open the lock " + lock.string() + ": " + std::strerror(errno));
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    fail(target_, "another run is writing it (lock " + lock.string() + "); nothing written");
  }
  staging_ = beside(target_, ".staging-" + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  fs::create_directories(staging_, ec);
  if (ec) fail(target_, "cannot create " + staging_.string() + ": " + ec.message());
}

OutputFolder::~OutputFolder() {
  std::error_code ec;
  if (!committed_) fs::remove_all(staging_, ec);
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

void OutputFolder::commit() {
  std::error_code ec;
  if (fs::exists(target_, ec)) {
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
