#include "render/picture_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace conform::scenes {

namespace {

double at(const std::vector<std::vector<double>>& w, std::size_t k, std::size_t p) {
  return p < w[k].size() ? w[k][p] : std::nan("");
}

// The first frame from which panel p's wound stays within tol × its largest size of its final
// size; w.size() when the final frame has no wound for p (the panel does not count).
std::size_t settled_from(const std::vector<std::vector<double>>& w, std::size_t p, double tol) {
  const std::size_t m = w.size();
  const double last = at(w, m - 1, p);
  if (!std::isfinite(last)) return m;
  double largest = 0;
  for (std::size_t k = 0; k < m; ++k)
    if (std::isfinite(at(w, k, p))) largest = std::max(largest, std::abs(at(w, k, p)));
  std::size_t k = m - 1;
  while (k > 0 && std::isfinite(at(w, k - 1, p)) &&
         std::abs(at(w, k - 1, p) - last) <= tol * largest)
    --k;
  return k;
}

// Up to n frames of [a, b] nearest to steps evenly spaced from steps[a] to steps[b], distinct.
std::vector<std::size_t> spread(const std::vector<int>& steps, std::size_t a, std::size_t b,
                                std::size_t n) {
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < n; ++k) {
    const double target =
        n == 1 ? steps[b] : steps[a] + double(k) * (steps[b] - steps[a]) / double(n - 1);
    std::size_t best = a;
    for (std::size_t i = a; i <= b; ++i)
      if (std::abs(steps[i] - target) < std::abs(steps[best] - target)) best = i;
    if (out.empty() || best > out.back()) out.push_back(best);
  }
  return out;
}

}  // namespace

PictureChoice choose_pictures(const std::vector<int>& steps,
                              const std::vector<std::vector<double>>& wounds, std::size_t pictures,
                              double settle_fraction) {
  PictureChoice c;
  const std::size_t m = std::min(steps.size(), wounds.size());
  if (m == 0 || pictures == 0) return c;
  std::size_t panels = 0;
  for (std::size_t k = 0; k < m; ++k) panels = std::max(panels, wounds[k].size());
  std::size_t from = m, settled = 0;
  for (std::size_t k = 0; k < m && from == m; ++k)
    for (std::size_t p = 0; p < panels; ++p)
      if (std::isfinite(at(wounds, k, p))) from = k;
  for (std::size_t p = 0; p < panels; ++p) {
    const std::size_t s = settled_from(wounds, p, settle_fraction);
    if (s < m) settled = std::max(settled, s);
  }
  c.by_wound = from < m;
  c.from = c.by_wound ? from : 0;
  c.settled = c.by_wound ? std::max(settled, from) : m - 1;
  const bool tail = c.settled < m - 1;
  c.frames = spread(steps, c.from, c.settled, pictures - (tail ? 1 : 0));
  if (tail || c.frames.empty()) c.frames.push_back(m - 1);
  return c;
}

void PictureCandidates::add(std::vector<FrameSnapshot> frame) {
  if (frame.empty()) return;
  frames_.push_back(std::move(frame));
  while (frames_.size() > budget_) thin();
}

bool PictureCandidates::worth_offering(int step, const std::vector<double>& wounds,
                                       int run_steps) const {
  if (frames_.empty()) return true;
  const auto& last = frames_.back();
  if (double(step - last.front().step) * double(budget_) >= double(run_steps)) return true;
  const std::vector<double> kept = largest_wounds();
  for (std::size_t p = 0; p < wounds.size() && p < last.size(); ++p) {
    const double w = wounds[p], before = last[p].wound;
    if (std::isfinite(w) != std::isfinite(before)) return true;
    if (!std::isfinite(w)) continue;
    const double largest = std::max(std::abs(w), p < kept.size() ? kept[p] : 0.0);
    if (std::abs(w - before) * double(budget_) > largest) return true;
  }
  return false;
}

PictureChoice PictureCandidates::choose(std::size_t pictures) const {
  std::vector<int> steps;
  std::vector<std::vector<double>> wounds;
  for (const auto& f : frames_) {
    steps.push_back(f.front().step);
    wounds.emplace_back();
    for (const auto& panel : f) wounds.back().push_back(panel.wound);
  }
  return choose_pictures(steps, wounds, pictures);
}

// How much frame i (neither the first nor the last) matters: see the class's comment. A frame
// where a wound first appears is always kept.
double PictureCandidates::importance(std::size_t i, const std::vector<double>& scale) const {
  const auto& before = frames_[i - 1];
  const auto& here = frames_[i];
  const auto& after = frames_[i + 1];
  double change = 0;
  for (std::size_t p = 0; p < here.size() && p < scale.size(); ++p) {
    const double a = p < before.size() ? before[p].wound : std::nan("");
    const double b = here[p].wound;
    const double c = p < after.size() ? after[p].wound : std::nan("");
    if (std::isfinite(b) && !std::isfinite(a)) return std::numeric_limits<double>::infinity();
    if (std::isfinite(a) && std::isfinite(c) && scale[p] > 0)
      change = std::max(change, std::abs(c - a) / scale[p]);
  }
  const double span = frames_.back().front().step - frames_.front().front().step;
  const double gap = span > 0 ? (after.front().step - before.front().step) / span : 0.0;
  return std::max(change, gap);
}

// Each panel's largest |wound| over the frames kept (0 where it has none).
std::vector<double> PictureCandidates::largest_wounds() const {
  std::vector<double> scale;
  for (const auto& f : frames_)
    for (std::size_t p = 0; p < f.size(); ++p) {
      if (scale.size() <= p) scale.resize(p + 1, 0.0);
      if (std::isfinite(f[p].wound)) scale[p] = std::max(scale[p], std::abs(f[p].wound));
    }
  return scale;
}

void PictureCandidates::thin() {
  const std::vector<double> scale = largest_wounds();
  std::size_t least = 1;
  double least_importance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i + 1 < frames_.size(); ++i) {
    const double v = importance(i, scale);
    if (v < least_importance) least = i, least_importance = v;
  }
  frames_.erase(frames_.begin() + static_cast<std::ptrdiff_t>(least));
}

}  // namespace conform::scenes
