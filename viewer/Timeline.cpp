#include "viewer/Timeline.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>

#include "core/Error.h"

namespace flipscope::viewer {

namespace {
std::vector<int> sortedUnique(std::vector<int> frames) {
  if (frames.empty()) throw InputError("timeline: no frames to show");
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}
}  // namespace

Timeline::Timeline(std::vector<int> frames) : mFrames(sortedUnique(std::move(frames))) {}

void Timeline::setFrames(std::vector<int> frames) {
  const int current = frame();
  mFrames = sortedUnique(std::move(frames));
  mIndex = nearestIndex(current);
}

void Timeline::setPlaying(bool playing) {
  mPlaying = playing;
  if (!playing) mAccumulatedFrames = 0;
}

void Timeline::setSpeed(double framesPerSecond) {
  if (std::isnan(framesPerSecond)) throw InputError("timeline: the playback speed is not a number");
  mSpeed = std::clamp(framesPerSecond, 0.1, 240.0);
}

void Timeline::stepForward() {
  const std::size_t last = mFrames.size() - 1;
  moveTo(mIndex < last ? mIndex + 1 : (mLoop ? 0 : last), +1);
}

void Timeline::stepBackward() {
  const std::size_t last = mFrames.size() - 1;
  moveTo(mIndex > 0 ? mIndex - 1 : (mLoop ? last : 0), -1);
}

void Timeline::home() { moveTo(0, -1); }

void Timeline::end() { moveTo(mFrames.size() - 1, +1); }

void Timeline::seek(int frame) {
  const std::size_t index = nearestIndex(frame);
  moveTo(index, mFrames[index] > this->frame() ? +1 : -1);
}

bool Timeline::update(double dtSeconds) {
  if (!mPlaying) {
    mAccumulatedFrames = 0;
    return false;
  }
  if (!(dtSeconds > 0)) return false;
  // The cap keeps the arithmetic finite for an absurd dt; the epsilon forgives sums of frame times
  // that round to just under a whole frame.
  mAccumulatedFrames = std::min(mAccumulatedFrames + dtSeconds * mSpeed, 1e15);
  const double steps = std::floor(mAccumulatedFrames + 1e-9);
  if (steps < 1) return false;
  mAccumulatedFrames = std::max(0.0, mAccumulatedFrames - steps);

  const int before = frame();
  const std::size_t size = mFrames.size();
  if (mLoop) {
    // n steps around a loop of `size` frames land where n mod size steps do.
    const auto shift = static_cast<std::size_t>(std::fmod(steps, static_cast<double>(size)));
    moveTo(mReverse ? (mIndex + size - shift) % size : (mIndex + shift) % size, mReverse ? -1 : +1);
  } else {
    const std::size_t remaining = mReverse ? mIndex : size - 1 - mIndex;
    const auto taken = static_cast<std::size_t>(std::min(steps, static_cast<double>(remaining)));
    moveTo(mReverse ? mIndex - taken : mIndex + taken, mReverse ? -1 : +1);
    if (steps >= static_cast<double>(remaining)) setPlaying(false);
  }
  return frame() != before;
}

void Timeline::moveTo(std::size_t index, int direction) {
  if (index != mIndex) mDirection = direction;
  mIndex = index;
}

std::size_t Timeline::nearestIndex(int frame) const {
  const auto above = std::lower_bound(mFrames.begin(), mFrames.end(), frame);
  if (above == mFrames.begin()) return 0;
  const auto below = std::prev(above);
  // Differences in 64 bits: frame numbers may span the whole int range.
  if (above == mFrames.end() || std::int64_t{frame} - *below <= std::int64_t{*above} - frame)
    return static_cast<std::size_t>(below - mFrames.begin());
  return static_cast<std::size_t>(above - mFrames.begin());
}

}  // namespace flipscope::viewer
