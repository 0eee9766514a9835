#include "viewer/ViewerScript.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "core/AtomicFile.h"
#include "core/Error.h"

namespace flipscope::viewer {

namespace {

constexpr std::string_view kSpaces = " \t";

std::string_view trimmed(std::string_view text) {
  const std::size_t begin = text.find_first_not_of(kSpaces);
  if (begin == std::string_view::npos) return {};
  return text.substr(begin, text.find_last_not_of(kSpaces) - begin + 1);
}

/// One line of a script being parsed: its words and the errors that name the file and line.
class ScriptLine {
 public:
  ScriptLine(std::string_view text, int number, const std::filesystem::path& file)
      : mText(text), mNumber(number), mFile(file) {
    for (std::size_t at = text.find_first_not_of(kSpaces); at != std::string_view::npos;
         at = text.find_first_not_of(kSpaces, at)) {
      const std::size_t end = std::min(text.find_first_of(kSpaces, at), text.size());
      mWords.push_back({text.substr(at, end - at), at});
      at = end;
    }
  }

  std::size_t size() const { return mWords.size(); }
  std::string_view word(std::size_t i) const { return mWords[i].text; }
  /// The text after word `i`, trimmed.
  std::string_view restAfter(std::size_t i) const {
    return trimmed(mText.substr(mWords[i].offset + mWords[i].text.size()));
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw FileError(mFile, "line " + std::to_string(mNumber) + ": " + message);
  }
  /// Fails unless the event (word 1) has exactly `count` arguments described by `usage`.
  void expectArguments(std::size_t count, std::string_view usage) const {
    if (mWords.size() != count + 2)
      fail(std::string(word(1)) + " expects " + (count == 0 ? "no arguments" : std::string(usage)) + ", got " +
           std::to_string(mWords.size() - 2) + " argument" + (mWords.size() == 3 ? "" : "s"));
  }
  /// Word `i` as a finite number; `what` names it in the error.
  double number(std::size_t i, std::string_view what) const {
    double value = 0;
    const std::string_view text = word(i);
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
      fail("'" + std::string(text) + "' is not a number (expected " + std::string(what) + ")");
    return value;
  }
  /// Word `i` as an int; `what` names it in the error.
  int integer(std::size_t i, std::string_view what) const {
    int value = 0;
    const std::string_view text = word(i);
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size())
      fail("'" + std::string(text) + "' is not an integer (expected " + std::string(what) + ")");
    return value;
  }

 private:
  struct Word {
    std::string_view text;
    std::size_t offset;  ///< in mText
  };
  std::string_view mText;
  int mNumber;
  const std::filesystem::path& mFile;
  std::vector<Word> mWords;
};

std::string lowerCase(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c); });
  return lower;
}

bool isKeyName(const std::string& name) {
  if (name.size() == 1) return (name[0] >= 'a' && name[0] <= 'z') || (name[0] >= '0' && name[0] <= '9');
  for (const char* known : {"space", "left", "right", "home", "end", "escape"})
    if (name == known) return true;
  return false;
}

ScriptEvent parseEvent(const ScriptLine& line) {
  ScriptEvent event;
  event.delaySeconds = line.number(0, "a delay in seconds >= 0");
  if (event.delaySeconds < 0) line.fail("the delay " + std::string(line.word(0)) + " is negative (expected >= 0)");
  if (line.size() < 2) line.fail("missing event after the delay");
  const std::string_view name = line.word(1);
  if (name == "key") {
    event.kind = ScriptEvent::Kind::Key;
    line.expectArguments(1, "a key NAME");
    event.key = lowerCase(line.word(2));
    if (!isKeyName(event.key))
      line.fail("unknown key '" + std::string(line.word(2)) +
                "' (expected space, left, right, home, end, escape, a letter a-z or a digit 0-9)");
  } else if (name == "drag") {
    event.kind = ScriptEvent::Kind::Drag;
    line.expectArguments(3, "BUTTON DX DY");
    const std::string_view button = line.word(2);
    if (button == "left") {
      event.button = 0;
    } else if (button == "right") {
      event.button = 1;
    } else if (button == "middle") {
      event.button = 2;
    } else {
      line.fail("unknown mouse button '" + std::string(button) + "' (expected left, right or middle)");
    }
    event.delta = {line.number(3, "DX in pixels"), line.number(4, "DY in pixels")};
  } else if (name == "scroll") {
    event.kind = ScriptEvent::Kind::Scroll;
    line.expectArguments(1, "DY (wheel steps)");
    event.delta = {0, line.number(2, "DY in wheel steps")};
  } else if (name == "frame") {
    event.kind = ScriptEvent::Kind::Frame;
    line.expectArguments(1, "a frame number N");
    event.frame = line.integer(2, "a frame number");
  } else if (name == "converge" || name == "quit") {
    event.kind = name == "quit" ? ScriptEvent::Kind::Quit : ScriptEvent::Kind::Converge;
    line.expectArguments(0, "");
  } else if (name == "screenshot" || name == "save-camera") {
    event.kind = name == "screenshot" ? ScriptEvent::Kind::Screenshot : ScriptEvent::Kind::SaveCamera;
    if (line.size() < 3) line.fail(std::string(name) + " expects a PATH");
    event.path = std::string(line.restAfter(1));
  } else {
    line.fail("unknown event '" + std::string(name) +
              "' (expected key, drag, scroll, frame, converge, screenshot, save-camera or quit)");
  }
  return event;
}

}  // namespace

std::vector<ScriptEvent> parseViewerScript(std::string_view text, const std::filesystem::path& file) {
  std::vector<ScriptEvent> events;
  int number = 0;
  while (!text.empty()) {
    ++number;
    const std::size_t newline = text.find('\n');
    std::string_view content = text.substr(0, newline);
    text = newline == std::string_view::npos ? std::string_view() : text.substr(newline + 1);
    content = content.substr(0, content.find('#'));
    if (!content.empty() && content.back() == '\r') content.remove_suffix(1);
    const ScriptLine line(content, number, file);
    if (line.size() == 0) continue;
    events.push_back(parseEvent(line));
    events.back().line = number;
  }
  return events;
}

std::vector<ScriptEvent> loadViewerScript(const std::filesystem::path& file) {
  return parseViewerScript(readTextFile(file, "viewer script"), file);
}

}  // namespace flipscope::viewer
