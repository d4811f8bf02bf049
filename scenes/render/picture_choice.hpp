// Which of a run's frames become pictures: the pictures go where the wound changes. A run of
// 180 steps whose tear settled by step 63 spent five of six evenly spaced pictures on a wound
// that no longer moved. Here every step may be offered; the candidates kept (within a budget)
// stay dense where the wound changes, and the pictures are spread in time from the first frame
// that shows a wound to the frame from which every panel's wound stays within
// `settle_fraction` of its final size. The last frame, which the run's figures describe, is
// always a picture.
#pragma once

#include <cstddef>
#include <vector>

#include "render/frame_snapshot.hpp"

namespace conform::scenes {

/// The frames chosen and the span they cover (indices into the frames given).
struct PictureChoice {
  std::vector<std::size_t> frames;  // increasing; the last frame included
  std::size_t from = 0;             // the first frame with a wound (0 without any)
  std::size_t settled = 0;          // the frame from which no wound changes any more
  bool by_wound = false;            // false: no frame had a wound, spread over the whole run
};

/// `steps[k]` is frame k's step (increasing) and `wounds[k][p]` the size of panel p's wound in
/// it (any unit, e.g. the largest gap), NaN where the panel has none yet. At most `pictures`
/// frames: the nearest to steps evenly spaced over [from, settled], plus the last frame when
/// the wound settled before it. Without any wound they are spread over the whole run.
PictureChoice choose_pictures(const std::vector<int>& steps,
                              const std::vector<std::vector<double>>& wounds, std::size_t pictures,
                              double settle_fraction = 0.02);

/// The frames offered for pictures, at most `budget` of them kept. The first and the last
/// offered are always kept; when over budget, the frame that matters least goes: the one with
/// the smallest max(change of its neighbours' wounds over the largest wound, time between its
/// neighbours over the whole span). So the frames kept thin out where nothing changes first.
class PictureCandidates {
 public:
  explicit PictureCandidates(std::size_t budget) : budget_(budget < 3 ? 3 : budget) {}

  void add(std::vector<FrameSnapshot> frame);
  /// Whether a frame at `step` whose panels have these wounds is worth a snapshot, in a run of
  /// `run_steps`: the first frame; one where a wound appears or vanishes, or moved by more than
  /// 1/budget of the largest wound since the last frame kept; one run_steps/budget steps after
  /// it. Any other would be thinned away at once, and a snapshot costs a fraction of a step.
  bool worth_offering(int step, const std::vector<double>& wounds, int run_steps) const;
  const std::vector<std::vector<FrameSnapshot>>& frames() const { return frames_; }
  bool empty() const { return frames_.empty(); }
  /// choose_pictures over the frames kept.
  PictureChoice choose(std::size_t pictures) const;

 private:
  std::vector<double> largest_wounds() const;
  double importance(std::size_t i, const std::vector<double>& scale) const;
  void thin();

  std::size_t budget_;
  std::vector<std::vector<FrameSnapshot>> frames_;
};

}  // namespace conform::scenes
