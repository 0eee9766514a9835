#include "viewer/FrameTimeHistory.h"

namespace flipscope::viewer {

void FrameTimeHistory::add(double timeSeconds, double frameMs, std::uint64_t bricksUploaded) {
  mSamples.push_back({timeSeconds, float(frameMs), float(bricksUploaded)});
  while (!mSamples.empty() && mSamples.front().time < timeSeconds - mSeconds) mSamples.pop_front();
  ++mFrames;
}

std::vector<float> FrameTimeHistory::frameMs() const {
  std::vector<float> out;
  for (const Sample& s : mSamples) out.push_back(s.ms);
  return out;
}

std::vector<float> FrameTimeHistory::bricksUploaded() const {
  std::vector<float> out;
  for (const Sample& s : mSamples) out.push_back(s.bricks);
  return out;
}

double FrameTimeHistory::fps() const {
  if (mSamples.size() < 2) return 0;
  const double span = mSamples.back().time - mSamples.front().time;
  return span > 0 ? double(mSamples.size() - 1) / span : 0;
}

}  // namespace flipscope::viewer
