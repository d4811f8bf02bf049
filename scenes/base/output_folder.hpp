// A run's output folder, written atomically: the run writes into a staging folder beside
// `--out` (.NAME.staging-PID) and, when it succeeds, commit() swaps it into place in one
// rename (renameat2 RENAME_EXCHANGE) and deletes the earlier results. A failed or interrupted
// run leaves the earlier results untouched and removes its staging folder, so every file in
// `--out` is from one complete run.
//
// The folder is the user's: a run replaces only an earlier Conform result, which it knows by the
// marker file every result holds (.conform-run). It refuses, touching nothing, an --out that is
// the current folder or one of its ancestors, that holds one of the run's inputs, or that is not
// empty and has no marker. A second run into the same `--out` while one is writing is refused:
// an exclusive flock on .NAME.lock beside it, released when the process ends however it ends;
// the lock file is removed when the run ends (while still locked: an opener re-checks that the
// file it locked is still the one on disk). Staging folders left by killed runs are removed by
// the next run into the same --out.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace conform::scenes {

/// The name of the marker file in every result.
inline constexpr const char* kRunMarker = ".conform-run";

/// An --out that is not the run's to replace (the command exits 2; nothing was touched).
class OutputRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws OutputRefused when OutputFolder would refuse `target`, without touching anything: a
/// command checks its --out before its long work (the folder checks again under its lock).
void check_output_folder(const std::filesystem::path& target,
                         const std::vector<std::filesystem::path>& inputs);

class OutputFolder {
 public:
  /// Checks `target` against the rules above (throws OutputRefused naming the reason), locks it,
  /// removes stale staging folders and creates an empty staging folder holding the marker.
  /// `inputs` are the run's input files (model, scalpel, scene file). Throws std::runtime_error
  /// naming the folder when it is busy (another run holds the lock) or cannot be created.
  explicit OutputFolder(std::filesystem::path target,
                        const std::vector<std::filesystem::path>& inputs = {});
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  /// Where the run writes.
  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  /// Puts the staging folder in place of `target`. Throws std::runtime_error when it cannot.
  void commit();

 private:
  void lock();
  void unlock();
  void remove_stale_staging() const;
  void make_staging();

  std::filesystem::path target_, staging_, lock_path_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

}  // namespace conform::scenes
