// One sweep per folder: a sweep (and --gather) holds an exclusive flock on the sweep folder
// itself, so no lock file is left behind. The point runs inherit the locked descriptor: the
// points of a killed sweep hold the lock until the last of them has ended, and a resume is
// refused rather than run beside them.
#pragma once

#include <filesystem>
#include <stdexcept>

namespace conform::scenes {

/// Thrown when another process holds the folder's lock.
class SweepBusy : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

class SweepLock {
 public:
  /// Locks the existing folder `dir` without waiting. Throws SweepBusy when another sweep (or
  /// one of its point runs) holds it, std::runtime_error when the folder cannot be opened. A file
  /// system without flock gives a warning on stderr and no lock.
  explicit SweepLock(const std::filesystem::path& dir);
  ~SweepLock();
  SweepLock(const SweepLock&) = delete;
  SweepLock& operator=(const SweepLock&) = delete;

  /// The locked descriptor (close-on-exec; -1 without a lock), for children to inherit.
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

}  // namespace conform::scenes
