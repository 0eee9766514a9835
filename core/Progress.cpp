#include "core/Progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "core/Elapsed.h"

namespace flipscope {

Progress::Progress(std::string label, std::uint64_t total, std::string unit, Mode mode)
    : mLabel(std::move(label)), mUnit(std::move(unit)), mTotal(total), mStart(std::chrono::steady_clock::now()), mMode(mode) {
  if (mMode == Mode::Auto) mMode = ::isatty(STDERR_FILENO) ? Mode::Bar : Mode::SummaryOnly;
  if (mMode == Mode::Bar) mThread = std::thread([this] { drawLoop(); });
}

Progress::~Progress() {
  {
    std::lock_guard lock(mMutex);
    mStop = true;
  }
  mWake.notify_all();
  if (mThread.joinable()) mThread.join();
}

void Progress::setLabel(std::string label) {
  std::lock_guard lock(mMutex);
  mLabel = std::move(label);
}

double Progress::elapsedSeconds() const { return secondsSince(mStart); }

std::string Progress::humanCount(double v) {
  const char* suffix = "";
  if (v >= 1e9) v /= 1e9, suffix = " G";
  else if (v >= 1e6) v /= 1e6, suffix = " M";
  else if (v >= 1e3) v /= 1e3, suffix = " k";
  char buf[64];
  std::snprintf(buf, sizeof buf, v < 10 && *suffix ? "%.2f%s" : "%.1f%s", v, suffix);
  return buf;
}

std::string Progress::line(bool final) const {
  double seconds = elapsedSeconds();
  double done = double(mDone.load());
  double total = double(mTotal.load());
  double rate = seconds > 0 ? done / seconds : 0;
  char buf[256];
  std::string text = mLabel + ": ";
  if (!final && total > 0) {
    double f = std::min(1.0, done / total);
    int width = 24, filled = int(std::lround(f * width));
    text += "[" + std::string(filled, '#') + std::string(width - filled, '.') + "] ";
    std::snprintf(buf, sizeof buf, "%3.0f%% ", f * 100);
    text += buf;
  }
  text += humanCount(done) + " " + mUnit;
  std::snprintf(buf, sizeof buf, final ? " in %.2f s" : " %.1f s", seconds);
  text += buf;
  text += " (" + humanCount(rate) + " " + mUnit + "/s)";
  if (!final && total > 0 && rate > 0 && done < total) {
    std::snprintf(buf, sizeof buf, " ETA %.0f s", (total - done) / rate);
    text += buf;
  }
  return text;
}

void Progress::drawLoop() {
  std::unique_lock lock(mMutex);
  while (!mStop && !mFinished) {
    std::fprintf(stderr, "\r\033[K%s", line(false).c_str());
    std::fflush(stderr);
    mWake.wait_for(lock, std::chrono::milliseconds(200));
  }
}

void Progress::finish(const std::string& extra) {
  {
    std::lock_guard lock(mMutex);
    if (mFinished) return;
    mFinished = true;
  }
  mWake.notify_all();
  if (mThread.joinable()) mThread.join();
  if (mMode == Mode::Silent) return;
  std::lock_guard lock(mMutex);
  std::fprintf(stderr, "%s%s%s\n", mMode == Mode::Bar ? "\r\033[K" : "", line(true).c_str(), extra.c_str());
}

}  // namespace flipscope
