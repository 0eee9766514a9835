// InputSequence: expands the input names of `flipscope convert` into frames.
// Patterns: `name_####.ext` (a run of '#' is the zero-padded frame number), printf `%04d` /
// `%d`, and `{}` (unpadded frame number). Several inputs per frame (e.g. FLIP and spray files)
// merge into one frame. With `frames` unset, patterns are matched against the directory
// listing and every frame number found for the first pattern is used; inputs without a
// pattern form a single frame (number `frames->first`, or 0); beside patterned inputs they
// belong to every frame (e.g. a static obstacle). A pattern in a directory name needs `frames`.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace flipscope {

struct FrameInput {
  int frame = 0;
  std::vector<std::filesystem::path> files;
};

struct FrameRange {
  int first = 0;
  int last = 0;  ///< inclusive
};

/// Parses "A-B" or "A" (throws InputError naming the text).
FrameRange parseFrameRange(const std::string& text);

/// Throws InputError/FileError when a pattern matches nothing or an expected file is missing
/// (names the missing path and the frame).
std::vector<FrameInput> expandInputs(const std::vector<std::string>& inputs, std::optional<FrameRange> frames);

/// The first frame expandInputs(inputs, nullopt) would give, without checking the files of the
/// others: the smallest frame number of the first pattern's files, or 0 when no input has a
/// pattern. Throws as expandInputs when that pattern matches nothing.
int firstFrameOf(const std::vector<std::string>& inputs);

/// Whether `inputs` name a brick store rather than particle files: one input, a directory.
bool isStoreDirectory(const std::vector<std::string>& inputs);

/// Substitutes `frame` into a pattern; returns the input unchanged if it has no pattern.
std::string substituteFrame(const std::string& pattern, int frame);
bool hasFramePattern(const std::string& input);

}  // namespace flipscope
