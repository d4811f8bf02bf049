#include "base/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace conform::scenes {

Progress::Progress(std::string label, std::string unit, long total, double quiet_s)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      quiet_s_(quiet_s),
      tty_(::isatty(STDERR_FILENO) == 1) {}

void Progress::update(long done, const std::string& note) {
  done_ = done;
  note_ = note;
  if (finished_) return;
  if (!shown_) {
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (s < quiet_s_) return;
  }
  draw(false);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (shown_) draw(true);
}

void Progress::line(const std::string& text) {
  std::cerr << (tty_ && shown_ ? "\r\033[K" : "") << text << "\n";
  if (tty_ && shown_ && !finished_) draw(false);
  std::cerr << std::flush;
}

void Progress::draw(bool last) {
  const int percent = total_ > 0 ? int(100 * done_ / total_) : 100;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  char tail[160];
  std::snprintf(tail, sizeof tail, " %3d%% (%s %ld of %ld, %.1f s)%s%s", percent, unit_.c_str(),
                done_, total_, s, note_.empty() ? "" : ", ", note_.c_str());
  if (tty_) {
    if (percent == last_percent_ && !last) return;
    last_percent_ = percent;
    const int width = 30, filled = width * percent / 100;
    std::cerr << "\r\033[K" << label_ << " [" << std::string(std::size_t(filled), '#')
              << std::string(std::size_t(width - filled), '.') << "]" << tail << (last ? "\n" : "")
              << std::flush;
  } else {
    const int tenth = percent / 10;
    if (tenth == last_tenth_) return;  // the last line too, when 100 % was already written
    last_tenth_ = tenth;
    std::cerr << label_ << ":" << tail << "\n" << std::flush;
  }
  shown_ = true;
}

}  // namespace conform::scenes
