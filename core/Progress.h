// Progress of long work (convert, synth): a live bar with rate and ETA on stderr when stderr
// is a terminal, otherwise one summary line when the work finishes. advance() is thread safe
// and cheap (one relaxed atomic add); drawing happens on a background thread.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace flipscope {

class Progress {
 public:
  enum class Mode { Auto, Bar, SummaryOnly, Silent };

  /// `total` 0 means unknown (no ETA). `unit` names what is counted ("particles").
  Progress(std::string label, std::uint64_t total, std::string unit = "particles", Mode mode = Mode::Auto);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(std::uint64_t n) { mDone.fetch_add(n, std::memory_order_relaxed); }
  void setTotal(std::uint64_t total) { mTotal.store(total, std::memory_order_relaxed); }
  /// Replaces the label (e.g. "convert frame 12/40").
  void setLabel(std::string label);
  std::uint64_t done() const { return mDone.load(std::memory_order_relaxed); }
  double elapsedSeconds() const;
  /// Stops the bar and prints the summary line (once); `extra` is appended to it.
  void finish(const std::string& extra = "");

  /// "1.23 G", "45.6 M", "789 k" style number.
  static std::string humanCount(double v);

 private:
  void drawLoop();
  std::string line(bool final) const;

  mutable std::mutex mMutex;
  std::string mLabel;
  std::string mUnit;
  std::atomic<std::uint64_t> mTotal;
  std::atomic<std::uint64_t> mDone{0};
  std::chrono::steady_clock::time_point mStart;
  Mode mMode;
  bool mFinished = false;
  bool mStop = false;
  std::condition_variable mWake;
  std::thread mThread;
};

}  // namespace flipscope
