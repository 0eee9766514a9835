// Timeline: the playhead over sparse frame numbers, stepping, seeking and timed playback.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <vector>

#include "core/Error.h"
#include "viewer/Timeline.h"

namespace flipscope::viewer {
namespace {

using Frames = std::vector<int>;

TEST(Timeline, SortsAndDropsDuplicatesAndStartsPausedOnTheFirstFrame) {
  const Timeline timeline({30, 10, 20, 10, 40, 30});
  EXPECT_EQ(timeline.frames(), (Frames{10, 20, 30, 40}));
  EXPECT_EQ(timeline.frame(), 10);
  EXPECT_EQ(timeline.index(), 0u);
  EXPECT_FALSE(timeline.playing());
  EXPECT_DOUBLE_EQ(timeline.speed(), 24);
  EXPECT_TRUE(timeline.loop());
  EXPECT_FALSE(timeline.reverse());
  EXPECT_EQ(timeline.direction(), 0);
}

TEST(Timeline, RefusesAnEmptyFrameList) {
  EXPECT_THROW(Timeline(Frames{}), InputError);
  Timeline timeline({1, 2});
  EXPECT_THROW(timeline.setFrames({}), InputError);
  EXPECT_EQ(timeline.frames(), (Frames{1, 2}));
}

TEST(Timeline, StepsAndWrapsWithLoop) {
  Timeline timeline({5, 7, 9});
  timeline.stepForward();
  EXPECT_EQ(timeline.frame(), 7);
  timeline.stepForward();
  timeline.stepForward();
  EXPECT_EQ(timeline.frame(), 5);
  EXPECT_EQ(timeline.direction(), +1);
  timeline.stepBackward();
  EXPECT_EQ(timeline.frame(), 9);
  EXPECT_EQ(timeline.index(), 2u);
  EXPECT_EQ(timeline.direction(), -1);
}

TEST(Timeline, StepsStopAtTheEndsWithoutLoop) {
  Timeline timeline({5, 7, 9});
  timeline.setLoop(false);
  timeline.stepBackward();
  EXPECT_EQ(timeline.frame(), 5);
  EXPECT_EQ(timeline.direction(), 0);  // a no-op move keeps the direction
  timeline.stepForward();
  timeline.stepForward();
  timeline.stepForward();
  EXPECT_EQ(timeline.frame(), 9);
  timeline.stepBackward();
  timeline.stepForward();
  timeline.stepForward();
  EXPECT_EQ(timeline.frame(), 9);
  EXPECT_EQ(timeline.direction(), +1);
}

TEST(Timeline, HomeAndEnd) {
  Timeline timeline({3, 1, 8, 4});
  timeline.end();
  EXPECT_EQ(timeline.frame(), 8);
  EXPECT_EQ(timeline.direction(), +1);
  timeline.home();
  EXPECT_EQ(timeline.frame(), 1);
  EXPECT_EQ(timeline.direction(), -1);
  timeline.home();
  EXPECT_EQ(timeline.direction(), -1);
}

TEST(Timeline, SeeksTheNearestFrameTiesToTheLowerOne) {
  Timeline timeline({0, 10, 20, 21});
  timeline.seek(14);
  EXPECT_EQ(timeline.frame(), 10);
  EXPECT_EQ(timeline.direction(), +1);
  timeline.seek(16);
  EXPECT_EQ(timeline.frame(), 20);
  timeline.seek(15);
  EXPECT_EQ(timeline.frame(), 10);
  EXPECT_EQ(timeline.direction(), -1);
  timeline.seek(20);
  timeline.seek(19);
  EXPECT_EQ(timeline.direction(), +1);  // unchanged frame: unchanged direction
  timeline.seek(-100);
  EXPECT_EQ(timeline.frame(), 0);
  timeline.seek(1000);
  EXPECT_EQ(timeline.frame(), 21);
  timeline.seek(INT_MIN);
  EXPECT_EQ(timeline.frame(), 0);
  timeline.seek(INT_MAX);
  EXPECT_EQ(timeline.frame(), 21);

  Timeline wide({INT_MIN, INT_MAX});
  wide.seek(0);  // -1 is the middle: 0 is nearer INT_MAX
  EXPECT_EQ(wide.frame(), INT_MAX);
  wide.seek(-1);
  EXPECT_EQ(wide.frame(), INT_MIN);
}

TEST(Timeline, PlaysAtItsSpeed) {
  Frames frames;
  for (int i = 0; i < 100; ++i) frames.push_back(2 * i);
  Timeline timeline(frames);
  timeline.setPlaying(true);
  EXPECT_TRUE(timeline.update(0.5));
  EXPECT_EQ(timeline.index(), 12u);
  EXPECT_EQ(timeline.direction(), +1);
  // A frame's time in small slices: one step once they add up to 1/24 s.
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(timeline.update(1.0 / 120));
  EXPECT_TRUE(timeline.update(1.0 / 120));
  EXPECT_EQ(timeline.index(), 13u);
  timeline.setSpeed(10);
  EXPECT_TRUE(timeline.update(1.0));
  EXPECT_EQ(timeline.index(), 23u);
}

TEST(Timeline, PlayWrapsAroundALoop) {
  Timeline timeline({1, 2, 3, 4, 5});
  timeline.setPlaying(true);
  EXPECT_TRUE(timeline.update(0.5));  // 12 steps = twice round and 2 more
  EXPECT_EQ(timeline.frame(), 3);
  EXPECT_FALSE(timeline.update(5.0 / 24));  // 5 steps: once round
  EXPECT_EQ(timeline.frame(), 3);
  EXPECT_TRUE(timeline.playing());
  timeline.setReverse(true);
  EXPECT_TRUE(timeline.update(4.0 / 24));
  EXPECT_EQ(timeline.frame(), 4);
  EXPECT_EQ(timeline.direction(), -1);
  timeline.update(1e300);  // absurd times stay finite
  EXPECT_GE(timeline.frame(), 1);
  EXPECT_LE(timeline.frame(), 5);
}

TEST(Timeline, PausedDoesNothingAndDropsTime) {
  Timeline timeline({1, 2, 3});
  EXPECT_FALSE(timeline.update(10));
  EXPECT_EQ(timeline.frame(), 1);
  timeline.togglePlaying();
  EXPECT_TRUE(timeline.playing());
  EXPECT_FALSE(timeline.update(0.03));  // most of a frame's 1/24 s
  timeline.togglePlaying();
  EXPECT_FALSE(timeline.playing());
  timeline.setPlaying(true);
  EXPECT_FALSE(timeline.update(0.03));  // the earlier 0.03 s were dropped
  EXPECT_EQ(timeline.frame(), 1);
  EXPECT_FALSE(timeline.update(0));
  EXPECT_FALSE(timeline.update(-1));
  EXPECT_TRUE(timeline.update(0.02));
  EXPECT_EQ(timeline.frame(), 2);
}

TEST(Timeline, StopsAtTheEndWithoutLoop) {
  Timeline timeline({1, 2, 3, 4, 5});
  timeline.setLoop(false);
  timeline.setPlaying(true);
  EXPECT_TRUE(timeline.update(2.0 / 24));
  EXPECT_EQ(timeline.frame(), 3);
  EXPECT_TRUE(timeline.playing());
  EXPECT_TRUE(timeline.update(0.5));
  EXPECT_EQ(timeline.frame(), 5);
  EXPECT_FALSE(timeline.playing());
  EXPECT_FALSE(timeline.update(0.5));
  EXPECT_EQ(timeline.frame(), 5);

  timeline.setReverse(true);
  timeline.setPlaying(true);
  EXPECT_TRUE(timeline.update(3.0 / 24));
  EXPECT_EQ(timeline.frame(), 2);
  EXPECT_EQ(timeline.direction(), -1);
  EXPECT_TRUE(timeline.update(1.0 / 24));
  EXPECT_EQ(timeline.frame(), 1);
  EXPECT_FALSE(timeline.playing());  // stops on arriving at the first frame
}

TEST(Timeline, ClampsTheSpeed) {
  Timeline timeline({1});
  timeline.setSpeed(1000);
  EXPECT_DOUBLE_EQ(timeline.speed(), 240);
  timeline.setSpeed(0);
  EXPECT_DOUBLE_EQ(timeline.speed(), 0.1);
  timeline.setSpeed(-5);
  EXPECT_DOUBLE_EQ(timeline.speed(), 0.1);
  timeline.setSpeed(30);
  EXPECT_DOUBLE_EQ(timeline.speed(), 30);
  EXPECT_THROW(timeline.setSpeed(std::nan("")), InputError);
  EXPECT_DOUBLE_EQ(timeline.speed(), 30);
}

TEST(Timeline, NewFramesKeepTheCurrentFrameOrTheNearest) {
  Timeline timeline({10, 20, 30});
  timeline.seek(20);
  timeline.setFrames({40, 20, 10, 30, 50});
  EXPECT_EQ(timeline.frame(), 20);
  EXPECT_EQ(timeline.index(), 1u);
  EXPECT_EQ(timeline.frames().size(), 5u);
  timeline.setFrames({0, 18, 23, 100});
  EXPECT_EQ(timeline.frame(), 18);
  timeline.setFrames({16, 20});
  EXPECT_EQ(timeline.frame(), 16);  // a tie: the lower one
  EXPECT_EQ(timeline.index(), 0u);
  timeline.setFrames({90});
  EXPECT_EQ(timeline.frame(), 90);
}

}  // namespace
}  // namespace flipscope::viewer
