// The playhead of `flipscope view`: which of a cache's frames is shown, stepping, seeking and
// timed playback, independent of any window.
#pragma once

#include <cstddef>
#include <vector>

namespace flipscope::viewer {

/// The playhead of `flipscope view` over a cache's frame numbers (not necessarily contiguous).
/// Not thread safe.
class Timeline {
 public:
  /// `frames`: the available frame numbers (any order, duplicates allowed: sorted and made
  /// unique). Starts paused on the first frame. Throws InputError when empty.
  explicit Timeline(std::vector<int> frames);
  /// New frame list (frames arriving while a cache converts): keeps the current frame when it
  /// is still present, else the nearest one (ties: the lower one). Throws InputError when empty.
  void setFrames(std::vector<int> frames);
  const std::vector<int>& frames() const { return mFrames; }
  int frame() const { return mFrames[mIndex]; }  ///< the current frame number
  std::size_t index() const { return mIndex; }   ///< its position in frames()

  bool playing() const { return mPlaying; }
  /// Pausing drops the time accumulated towards the next frame.
  void setPlaying(bool playing);
  void togglePlaying() { setPlaying(!mPlaying); }
  double speed() const { return mSpeed; }  ///< frames per second while playing; default 24
  /// Clamped to [0.1, 240] frames per second. Throws InputError for NaN.
  void setSpeed(double framesPerSecond);
  bool loop() const { return mLoop; }  ///< default true
  void setLoop(bool loop) { mLoop = loop; }
  bool reverse() const { return mReverse; }  ///< playing backwards; default false
  void setReverse(bool reverse) { mReverse = reverse; }
  /// The direction the playhead last moved: +1 (to the next frame, wrapping included), -1 (to
  /// the previous one), or 0 before any move. A call that leaves the frame unchanged keeps it.
  /// Steers read-ahead.
  int direction() const { return mDirection; }

  void stepForward();   ///< next frame (wraps to the first with loop on, else stays on the last)
  void stepBackward();  ///< previous frame (wraps to the last with loop on, else stays on the first)
  void home();          ///< first frame
  void end();           ///< last frame
  /// Jumps to `frame`, or the nearest available frame (ties: the lower one).
  void seek(int frame);
  /// Advances the playhead while playing: time accumulates, and every 1/speed seconds one frame
  /// is taken, in the direction reverse() says (several if dt spans several; with loop on, n
  /// steps land where taking them one by one would, in constant time). Without loop, playing
  /// stops (playing() becomes false) when the last (or, reversed, the first) frame is reached.
  /// Returns true when the current frame changed. Does nothing for dt <= 0, nor when paused.
  bool update(double dtSeconds);

 private:
  /// Moves to frames()[index]; `direction` (+1 or -1) becomes direction() if the frame changes.
  void moveTo(std::size_t index, int direction);
  /// The index of `frame` or of the nearest available frame (ties: the lower one).
  std::size_t nearestIndex(int frame) const;

  std::vector<int> mFrames;
  std::size_t mIndex = 0;
  bool mPlaying = false;
  double mSpeed = 24;
  bool mLoop = true;
  bool mReverse = false;
  int mDirection = 0;
  double mAccumulatedFrames = 0;  ///< playing time (in frames) not yet spent on a step
};

}  // namespace flipscope::viewer
