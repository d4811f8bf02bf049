// A run's output folder, written atomically: the run writes into a staging folder beside
// `--out` (.NAME.staging-PID) and, when it succeeds, commit() swaps it into place in one
// rename (renameat2 RENAME_EXCHANGE) and deletes the earlier results. A failed or interrupted
// run leaves the earlier results untouched and removes its staging folder, so every file in
// `--out` is from one complete run. A second run into the same `--out` while one is writing is
// refused: an exclusive flock on .NAME.lock beside it, released when the process ends however
// it ends (the lock file itself stays, empty).
#pragma once

#include <filesystem>
#include <string>

namespace conform::scenes {

class OutputFolder {
 public:
  /// Locks `target` and creates an empty staging folder. Throws std::runtime_error naming the
  /// folder when it is busy (another run holds the lock) or cannot be created.
  explicit OutputFolder(std::filesystem::path target);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  /// Where the run writes.
  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  /// Puts the staging folder in place of `target`. Throws std::runtime_error when it cannot.
  void commit();

 private:
  std::filesystem::path target_, staging_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

}  // namespace conform::scenes
