// Progress of a long job on stderr: the scenes' steps, a sweep's points, the pictures' renders.
// On a terminal a bar redrawn in place; otherwise plain lines, at most one per tenth of the job
// (a log stays short). Nothing is shown while the job is in its first second, so a quick run
// stays quiet; once something was shown, finishing prints a last line (100 %).
#pragma once

#include <chrono>
#include <string>

namespace conform::scenes {

class Progress {
 public:
  /// `label` starts every line ("tear-opening", "sweep", "pictures"); `unit` names what is
  /// counted ("step", "point", "frame"). `quiet_s`: how long to wait before showing anything.
  Progress(std::string label, std::string unit, long total, double quiet_s = 1.0);
  ~Progress() { finish(); }

  /// `done` of the total are done; `note` is appended (e.g. "2 failed").
  void update(long done, const std::string& note = "");
  /// The last line, if anything was shown (idempotent).
  void finish();

  /// Writes a line of its own (e.g. a failure) above the bar, or as a plain line.
  void line(const std::string& text);

  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

 private:
  void draw(bool last);

  std::string label_, unit_, note_;
  long total_, done_ = 0;
  double quiet_s_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  bool tty_, shown_ = false, finished_ = false;
  int last_tenth_ = -1, last_percent_ = -1;
};

}  // namespace conform::scenes
