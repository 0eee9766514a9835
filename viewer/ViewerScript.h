// Scripted input of `flipscope view --script FILE`: the events a test feeds the viewer instead
// of a user's keyboard and mouse.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

namespace flipscope::viewer {

/// One scripted input event. Text format, one event a line, '#' starts a comment (anywhere in
/// a line), blank lines ignored, words separated by spaces or tabs, CRLF line ends accepted:
///   <delay-seconds> <event> [arguments]
/// where the delay (>= 0, a decimal number) is counted from the previous event. Events:
///   key NAME                 a key press: space left right home end escape, or a single letter
///                            a-z or digit 0-9 (f r s c w a d q e, ...); any case
///   drag BUTTON DX DY        a mouse drag by (DX, DY) pixels (y downwards) with BUTTON
///                            left|right|middle
///   scroll DY                the wheel by DY steps (positive: away from the user, zooms in)
///   frame N                  seek the timeline to frame N (integer)
///   converge                 wait until the shown frame has converged
///   screenshot PATH          save the shown image (PATH: rest of the line, trimmed; may contain
///                            spaces)
///   save-camera PATH         save the camera as JSON (PATH as for screenshot)
///   quit                     close the window
struct ScriptEvent {
  enum class Kind { Key, Drag, Scroll, Frame, Converge, Screenshot, SaveCamera, Quit };
  double delaySeconds = 0;
  Kind kind = Kind::Quit;
  std::string key;             ///< Key: the name, lower case
  int button = 0;              ///< Drag: 0 left, 1 right, 2 middle
  glm::dvec2 delta{0};         ///< Drag: pixels; Scroll: (0, steps)
  int frame = 0;               ///< Frame
  std::filesystem::path path;  ///< Screenshot, SaveCamera
  int line = 0;                ///< 1-based line in the script, for messages
};

/// Parses a script's text. Throws FileError naming `file`, the line number ("line 3: ...") and
/// what was expected, for an unknown event, a bad or negative delay, missing/extra/non-numeric
/// arguments, an unknown key or button.
std::vector<ScriptEvent> parseViewerScript(std::string_view text, const std::filesystem::path& file);
/// Reads and parses `file` (FileError when it cannot be read).
std::vector<ScriptEvent> loadViewerScript(const std::filesystem::path& file);

}  // namespace flipscope::viewer
