// ViewerScript: the text format of `flipscope view --script`, its events and its messages.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "TestSupport.h"
#include "core/Error.h"
#include "viewer/ViewerScript.h"

namespace flipscope::viewer {
namespace {

using Kind = ScriptEvent::Kind;

const std::filesystem::path kFile = "scripts/orbit.fsv";

/// gtest's HasSubstr without gmock (not linked into the tests).
::testing::AssertionResult hasSubstr(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

TEST(ViewerScript, ParsesEveryEvent) {
  const auto events = parseViewerScript(
      "0 key space\n"
      "0.5 key F\n"
      "1e-1 drag right -12.5 40\n"
      "2 scroll -3\n"
      "0 frame -17\n"
      "3 converge\n"
      "0 screenshot  out dir/shot 1.png  \n"
      "0.25 save-camera\tcam.json\n"
      "1 quit\n"
      "0 key escape\n"
      "0 key 7\n"
      "0 drag middle 0 -0.5\n",
      kFile);
  ASSERT_EQ(events.size(), 12u);
  for (std::size_t i = 0; i < events.size(); ++i) EXPECT_EQ(events[i].line, int(i) + 1);
  EXPECT_EQ(events[0].kind, Kind::Key);
  EXPECT_EQ(events[0].key, "space");
  EXPECT_EQ(events[0].delaySeconds, 0);
  EXPECT_EQ(events[1].key, "f");
  EXPECT_EQ(events[1].delaySeconds, 0.5);
  EXPECT_EQ(events[2].kind, Kind::Drag);
  EXPECT_EQ(events[2].delaySeconds, 0.1);
  EXPECT_EQ(events[2].button, 1);
  EXPECT_EQ(events[2].delta, glm::dvec2(-12.5, 40));
  EXPECT_EQ(events[3].kind, Kind::Scroll);
  EXPECT_EQ(events[3].delta, glm::dvec2(0, -3));
  EXPECT_EQ(events[4].kind, Kind::Frame);
  EXPECT_EQ(events[4].frame, -17);
  EXPECT_EQ(events[5].kind, Kind::Converge);
  EXPECT_EQ(events[5].delaySeconds, 3);
  EXPECT_EQ(events[6].kind, Kind::Screenshot);
  EXPECT_EQ(events[6].path, "out dir/shot 1.png");
  EXPECT_EQ(events[7].kind, Kind::SaveCamera);
  EXPECT_EQ(events[7].path, "cam.json");
  EXPECT_EQ(events[7].delaySeconds, 0.25);
  EXPECT_EQ(events[8].kind, Kind::Quit);
  EXPECT_EQ(events[9].key, "escape");
  EXPECT_EQ(events[10].key, "7");
  EXPECT_EQ(events[11].button, 2);
  EXPECT_EQ(events[11].delta, glm::dvec2(0, -0.5));
}

TEST(ViewerScript, SkipsCommentsAndBlankLinesAndAcceptsCrlf) {
  const auto events = parseViewerScript(
      "# orbit once round\r\n"
      "\r\n"
      "   \t\n"
      "1 key left   # turn\r\n"
      "0 screenshot a.png# no space before the comment\r\n"
      "\n"
      "2 quit\r\n"
      "# the end, without a newline",
      kFile);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].key, "left");
  EXPECT_EQ(events[0].line, 4);
  EXPECT_EQ(events[1].path, "a.png");
  EXPECT_EQ(events[1].line, 5);
  EXPECT_EQ(events[2].kind, Kind::Quit);
  EXPECT_EQ(events[2].line, 7);
  EXPECT_TRUE(parseViewerScript("", kFile).empty());
  EXPECT_TRUE(parseViewerScript("# nothing\n\n", kFile).empty());
}

struct BadScript {
  const char* text;
  int line;
  const char* problem;  ///< a part of the message naming what was wrong
};

TEST(ViewerScript, NamesFileLineAndProblemOfEachError) {
  const BadScript cases[] = {
      {"0 jump\n", 1, "unknown event 'jump'"},
      {"# c\n1.5x key a\n", 2, "'1.5x' is not a number"},
      {"0 quit\n\n-1 quit\n", 3, "negative"},
      {"key space\n", 1, "'key' is not a number"},
      {"nan quit\n", 1, "'nan' is not a number"},
      {"inf quit\n", 1, "'inf' is not a number"},
      {"0\n", 1, "missing event"},
      {"0 key\n", 1, "key expects a key NAME, got 0 arguments"},
      {"0 key a b\n", 1, "got 2 arguments"},
      {"0 key up\n", 1, "unknown key 'up'"},
      {"0 key ab\n", 1, "unknown key 'ab'"},
      {"0 drag left 1\n", 1, "drag expects BUTTON DX DY, got 2 arguments"},
      {"0 drag left 1 2 3\n", 1, "got 4 arguments"},
      {"0 drag top 1 2\n", 1, "unknown mouse button 'top'"},
      {"0 drag left 1 2px\n", 1, "'2px' is not a number"},
      {"0 scroll\n", 1, "scroll expects"},
      {"0 scroll up\n", 1, "'up' is not a number"},
      {"0 frame 1.5\n", 1, "'1.5' is not an integer"},
      {"0 frame 99999999999\n", 1, "'99999999999' is not an integer"},
      {"0 frame\n", 1, "frame expects a frame number"},
      {"0 converge now\n", 1, "converge expects no arguments, got 1 argument"},
      {"0 quit 1\r\n", 1, "quit expects no arguments"},
      {"0 screenshot   \n", 1, "screenshot expects a PATH"},
      {"0 save-camera # a comment only\n", 1, "save-camera expects a PATH"},
  };
  for (const BadScript& bad : cases) {
    try {
      parseViewerScript(bad.text, kFile);
      ADD_FAILURE() << "no error for: " << bad.text;
    } catch (const FileError& error) {
      EXPECT_EQ(error.path(), kFile);
      EXPECT_TRUE(hasSubstr(error.what(), kFile.string()));
      EXPECT_TRUE(hasSubstr(error.what(), "line " + std::to_string(bad.line) + ":"));
      EXPECT_TRUE(hasSubstr(error.what(), bad.problem));
    }
  }
}

TEST(ViewerScript, LoadsAFileAndNamesAMissingOne) {
  flipscope::testing::TempDir dir("viewer-script");
  const std::filesystem::path file = dir / "play.fsv";
  std::ofstream(file) << "0 frame 3\n1 quit\n";
  const auto events = loadViewerScript(file);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].frame, 3);
  EXPECT_EQ(events[1].kind, Kind::Quit);

  const std::filesystem::path missing = dir / "missing.fsv";
  try {
    loadViewerScript(missing);
    ADD_FAILURE() << "no error for a missing script";
  } catch (const FileError& error) {
    EXPECT_EQ(error.path(), missing);
    EXPECT_TRUE(hasSubstr(error.what(), missing.string()));
    EXPECT_TRUE(hasSubstr(error.what(), "cannot open viewer script")) << error.what();
  }
}

}  // namespace
}  // namespace flipscope::viewer
