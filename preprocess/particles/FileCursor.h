// FileCursor: a buffered sequential reader over a byte range of an InputFile, at its own offset,
// for readers that interleave several regions of one file (one cursor per array: VTK stores
// each attribute whole, one after the other). Reads through InputFile::readAt, so cursors of
// one file do not disturb each other. Also the text helpers those readers share: words and
// lines of a text header, and ASCII numbers parsed with std::from_chars. Not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope::detail {

/// Whitespace of text formats: space, \t, \n, \v, \f, \r.
inline bool isSpaceByte(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

class FileCursor {
 public:
  /// Reads [begin, end) of `file` (which must outlive the cursor), through a buffer of
  /// `bufferBytes`. end is clamped to the file size.
  FileCursor(InputFile& file, std::uint64_t begin, std::uint64_t end, std::size_t bufferBytes = 64 << 10);

  InputFile& file() const { return *mFile; }
  std::uint64_t offset() const { return mBufferStart + mAt; }
  std::uint64_t end() const { return mEnd; }
  std::uint64_t remaining() const { return mEnd - offset(); }
  bool atEnd() const { return offset() >= mEnd; }
  /// Moves to `offset` (<= end()); keeps the buffer when it holds that offset.
  void seek(std::uint64_t offset);

  /// The bytes from offset() on: at least `bytes` of them (fewer only at end()), and no more
  /// than the buffer. `bytes` must not exceed the buffer size.
  std::span<const char> window(std::size_t bytes);
  void advance(std::size_t bytes) { mAt += bytes; }
  /// Whether the last window() reaches end().
  bool windowAtEnd() const { return mBufferStart + mBuffer.size() >= mEnd; }
  /// Next byte without consuming it; -1 at end().
  int peek();
  /// Reads exactly `bytes`, or throws FileError saying the file ends inside `what`.
  void readExact(void* data, std::size_t bytes, const std::string& what);

  // ---- Text ----
  /// Skips whitespace, then returns the word up to the next whitespace (empty at end()). A word
  /// longer than `maxLength` throws FileError; so does a word that end() cuts (`what` names it):
  /// a text file ends with a line break, and a cut word may read as another value.
  std::string_view word(std::size_t maxLength, std::string_view what);
  /// Like word(), but stays on the current line: empty when the line (or the range) ends first.
  std::string_view wordOnLine(std::size_t maxLength, std::string_view what);
  /// The rest of the current line without its "\n" (and "\r"), the line break consumed. A line
  /// longer than `maxLength` throws FileError, and so does a range that ends before the line
  /// break (`what` names the line).
  std::string_view line(std::size_t maxLength, std::string_view what);
  /// Skips blanks (space, \t, \r) to the line break and consumes it; throws FileError when
  /// anything else comes first (`what` names the line) or the range ends.
  void endLine(std::string_view what);
  /// Skips `count` whitespace-separated words; throws FileError when the range ends first.
  /// `endTerminates`: the range end may close the last word (XML: the '<' of the end tag).
  void skipWords(std::uint64_t count, bool endTerminates, std::string_view what);
  /// Parses `count` whitespace-separated numbers into `out` (values of `type`: Float32 parses as
  /// float, everything else as double, then converted). Throws FileError on a malformed number
  /// or when the range ends first. `endTerminates` as in skipWords.
  void parseNumbers(float* out, std::size_t count, ValueType type, bool endTerminates, std::string_view what);

  /// A FileError "<path>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  void fill(std::size_t bytes);
  template <class Visit>
  void scanWords(std::uint64_t count, bool endTerminates, std::string_view what, Visit&& visit);

  InputFile* mFile;
  std::uint64_t mEnd;
  std::size_t mCapacity;
  std::vector<char> mBuffer;  ///< bytes [mBufferStart, mBufferStart + mBuffer.size()) of the file
  std::uint64_t mBufferStart = 0;
  std::size_t mAt = 0;  ///< offset() - mBufferStart
};

/// The float value of an ASCII number of type `type` (see FileCursor::parseNumbers); false when
/// `text` is not a number. Accepts a leading '+', "nan" and "inf"; out-of-range floats become
/// +-inf or 0 as a double cast would make them.
bool parseNumber(std::string_view text, ValueType type, float& value);

}  // namespace flipscope::detail
