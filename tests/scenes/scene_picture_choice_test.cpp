// Where a run's pictures go (scenes/render/picture_choice.hpp): spread in time from the first
// frame with a wound to the frame from which no wound changes any more, the last frame always;
// and the frames kept for them, within a budget, dense where the wound changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "render/picture_choice.hpp"

namespace {

using conform::scenes::choose_pictures;
using conform::scenes::FrameSnapshot;
using conform::scenes::PictureCandidates;
using Frames = std::vector<std::vector<double>>;
using Picks = std::vector<std::size_t>;
const double kNone = std::nan("");

std::vector<int> every_step(std::size_t m) {
  std::vector<int> steps(m);
  std::iota(steps.begin(), steps.end(), 0);
  return steps;
}

// A wound that appears at frame `from`, grows linearly until `until` and then holds: m frames.
double growing_at(std::size_t k, std::size_t from, std::size_t until) {
  return k < from ? kNone : double(std::min(k, until) - from + 1);
}
Frames growing(std::size_t m, std::size_t from, std::size_t until) {
  Frames w(m);
  for (std::size_t k = 0; k < m; ++k) w[k] = {growing_at(k, from, until)};
  return w;
}

TEST(PictureChoice, SpreadsOverTheWoundsGrowthAndKeepsTheLastFrame) {
  // 61 frames; the wound from frame 10 to 30, then still: 5 pictures, 4 over [10, 30] and 60.
  const auto c = choose_pictures(every_step(61), growing(61, 10, 30), 5);
  EXPECT_TRUE(c.by_wound);
  EXPECT_EQ(c.from, 10u);
  EXPECT_EQ(c.settled, 30u);
  EXPECT_EQ(c.frames, (Picks{10, 17, 23, 30, 60}));
}

TEST(PictureChoice, AWoundThatChangesToTheEndIsSpreadToTheEnd) {
  const auto c = choose_pictures(every_step(61), growing(61, 20, 60), 3);
  EXPECT_EQ(c.settled, 60u);
  EXPECT_EQ(c.frames, (Picks{20, 40, 60}));
}

TEST(PictureChoice, SpreadsInTimeNotInFrames) {
  // Frames at uneven steps: the pictures go to the frames nearest to evenly spaced times.
  const std::vector<int> steps = {0, 1, 2, 3, 4, 5, 50, 90, 100};
  Frames w(steps.size());
  for (std::size_t k = 0; k < steps.size(); ++k) w[k] = {double(steps[k] + 1)};
  EXPECT_EQ(choose_pictures(steps, w, 3).frames, (Picks{0, 6, 8}));
}

TEST(PictureChoice, SmallChangesBelowTheFractionCountAsSettled) {
  Frames w = growing(41, 0, 20);
  for (std::size_t k = 21; k < 41; ++k) w[k][0] += (k % 2 ? 0.1 : -0.1);  // 0.5 % of 21
  const auto c = choose_pictures(every_step(41), w, 3, 0.02);
  EXPECT_EQ(c.settled, 20u);
  EXPECT_EQ(c.frames, (Picks{0, 20, 40}));
  // A tighter fraction sees the wobble as change, to the end.
  EXPECT_EQ(choose_pictures(every_step(41), w, 3, 0.001).settled, 40u);
}

TEST(PictureChoice, EveryPanelMustHaveSettled) {
  // Panel 0 settles at 10, panel 1 (a wound opened later, e.g. geometric) at 50.
  Frames w(61, {kNone, kNone});
  for (std::size_t k = 5; k < 61; ++k) w[k][0] = double(std::min<std::size_t>(k, 10));
  for (std::size_t k = 40; k < 61; ++k) w[k][1] = double(std::min<std::size_t>(k, 50) - 39);
  const auto c = choose_pictures(every_step(61), w, 4);
  EXPECT_EQ(c.from, 5u);
  EXPECT_EQ(c.settled, 50u);
  EXPECT_EQ(c.frames.back(), 60u);
}

TEST(PictureChoice, WithoutAWoundTheRunIsSpreadEvenly) {
  const auto c = choose_pictures(every_step(11), Frames(11, {kNone}), 3);
  EXPECT_FALSE(c.by_wound);
  EXPECT_EQ(c.frames, (Picks{0, 5, 10}));
  EXPECT_EQ(choose_pictures(every_step(11), Frames(11, std::vector<double>{}), 1).frames,
            (Picks{10}));
}

TEST(PictureChoice, NeverMoreThanAskedNorRepeated) {
  for (std::size_t n = 1; n <= 8; ++n)
    for (std::size_t until : {3, 7, 12}) {
      const auto c = choose_pictures(every_step(13), growing(13, 2, until), n);
      EXPECT_LE(c.frames.size(), n);
      EXPECT_EQ(c.frames.back(), 12u);
      for (std::size_t i = 1; i < c.frames.size(); ++i) EXPECT_LT(c.frames[i - 1], c.frames[i]);
    }
  EXPECT_TRUE(choose_pictures({}, {}, 3).frames.empty());
}

// One panel's frame: only the step and the wound matter to the choice.
std::vector<FrameSnapshot> frame(int step, double wound) {
  FrameSnapshot s;
  s.step = step;
  s.wound = wound;
  return {s};
}

// A 600-step run whose wound grows from step 100 to 160, offered as a scene offers it: each
// step that the candidates find worth a snapshot.
PictureCandidates offer_run(std::size_t budget, int* offered) {
  PictureCandidates c(budget);
  *offered = 0;
  for (int step = 0; step <= 600; ++step) {
    const double w = growing_at(std::size_t(step), 100, 160);
    if (step < 600 && !c.worth_offering(step, {w}, 600)) continue;
    c.add(frame(step, w));
    ++*offered;
  }
  return c;
}

TEST(PictureCandidates, KeepsTheBudgetDenseWhereTheWoundChanges) {
  int offered = 0;
  const PictureCandidates c = offer_run(24, &offered);
  const auto& kept = c.frames();
  ASSERT_EQ(kept.size(), 24u);
  EXPECT_EQ(kept.front().front().step, 0);
  EXPECT_EQ(kept.back().front().step, 600);
  // A tenth of the run holds at least 40 % of the frames kept, the first with a wound among them.
  const auto in_growth = std::count_if(kept.begin(), kept.end(), [](const auto& f) {
    return f.front().step >= 100 && f.front().step <= 160;
  });
  EXPECT_GE(in_growth, 10);
  EXPECT_TRUE(
      std::any_of(kept.begin(), kept.end(), [](const auto& f) { return f.front().step == 100; }));
  // Snapshots were taken where they could be kept, not at every step.
  EXPECT_LT(offered, 200);
  // Six pictures: five from the wound's start to where it settled (160, or the next frame kept
  // when 160 was thinned), four of them while it grew, and the last step.
  const auto choice = c.choose(6);
  ASSERT_EQ(choice.frames.size(), 6u);
  EXPECT_EQ(kept[choice.from].front().step, 100);
  const int settled = kept[choice.settled].front().step;
  EXPECT_GE(settled, 160);
  EXPECT_LE(settled, 200);
  int growing_pictures = 0;
  for (std::size_t i = 0; i < 5; ++i) {
    const int step = kept[choice.frames[i]].front().step;
    EXPECT_GE(step, 100);
    EXPECT_LE(step, settled);
    growing_pictures += step <= 160;
  }
  EXPECT_GE(growing_pictures, 4);
  EXPECT_EQ(kept[choice.frames.back()].front().step, 600);
}

TEST(PictureCandidates, WithoutAWoundKeepsTheRunEvenlyCovered) {
  PictureCandidates c(10);
  for (int step = 0; step <= 100; ++step)
    if (step == 100 || c.worth_offering(step, {kNone}, 100)) c.add(frame(step, kNone));
  const auto& kept = c.frames();
  ASSERT_LE(kept.size(), 10u);
  for (std::size_t i = 1; i < kept.size(); ++i)
    EXPECT_LE(kept[i].front().step - kept[i - 1].front().step, 25);
}

}  // namespace
