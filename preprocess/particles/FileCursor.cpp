#include "preprocess/particles/FileCursor.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/Error.h"

namespace flipscope::detail {
namespace {

/// Longest number (or word of skipWords) that parseNumbers accepts: no real number is longer.
constexpr std::size_t kMaxNumberBytes = 255;

bool isBlankByte(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

template <class T>
bool parseFloating(const char* begin, const char* end, T& value) {
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ptr != end) return false;
  if (ec == std::errc()) return true;
  if (ec != std::errc::result_out_of_range) return false;
  // Out of range: what a cast from the exact value would give (+-inf, or +-0 for tiny values).
  bool negative = *begin == '-';
  bool tiny = false;
  for (const char* p = begin; p < end; ++p)
    if ((*p == 'e' || *p == 'E') && p + 1 < end && p[1] == '-') tiny = true;
  value = tiny ? T(negative ? -0.0 : 0.0)
               : (negative ? -std::numeric_limits<T>::infinity() : std::numeric_limits<T>::infinity());
  return true;
}

}  // namespace

bool parseNumber(std::string_view text, ValueType type, float& value) {
  if (!text.empty() && text[0] == '+') {
    text.remove_prefix(1);
    if (text.empty() || text[0] == '-' || text[0] == '+') return false;
  }
  if (text.empty()) return false;
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (type == ValueType::Float32) return parseFloating(begin, end, value);
  double wide = 0;
  if (!parseFloating(begin, end, wide)) return false;
  value = static_cast<float>(wide);
  return true;
}

FileCursor::FileCursor(InputFile& file, std::uint64_t begin, std::uint64_t end, std::size_t bufferBytes)
    : mFile(&file), mEnd(std::min(end, file.size())), mCapacity(std::max<std::size_t>(bufferBytes, 4096)) {
  mBufferStart = std::min(begin, mEnd);
}

void FileCursor::fail(const std::string& message) const { throw FileError(mFile->path(), message); }

void FileCursor::seek(std::uint64_t offset) {
  if (offset > mEnd)
    fail("cannot seek to byte " + std::to_string(offset) + ": past the end (byte " + std::to_string(mEnd) + ")");
  if (offset >= mBufferStart && offset <= mBufferStart + mBuffer.size()) {
    mAt = std::size_t(offset - mBufferStart);
    return;
  }
  mBuffer.clear();
  mBufferStart = offset;
  mAt = 0;
}

void FileCursor::fill(std::size_t bytes) {
  if (mBuffer.size() - mAt >= bytes) return;
  const std::uint64_t start = offset();
  const std::size_t kept = mBuffer.size() - mAt;
  if (kept) std::memmove(mBuffer.data(), mBuffer.data() + mAt, kept);
  mBufferStart = start;
  mAt = 0;
  const std::size_t want = std::size_t(std::min<std::uint64_t>(mCapacity, mEnd - start));
  if (want <= kept) {
    mBuffer.resize(kept);
    return;
  }
  mBuffer.resize(want);
  const std::size_t got = mFile->readAt(start + kept, mBuffer.data() + kept, want - kept);
  mBuffer.resize(kept + got);
  if (got < want - kept) mEnd = start + kept + got;  // the file is shorter than it was at open
}

std::span<const char> FileCursor::window(std::size_t bytes) {
  FLIPSCOPE_CHECK(bytes <= mCapacity, "bytes=" << bytes << " capacity=" << mCapacity);
  fill(bytes);
  return {mBuffer.data() + mAt, mBuffer.size() - mAt};
}

int FileCursor::peek() {
  fill(1);
  return mAt < mBuffer.size() ? static_cast<unsigned char>(mBuffer[mAt]) : -1;
}

void FileCursor::readExact(void* data, std::size_t bytes, const std::string& what) {
  if (bytes > remaining())
    fail("truncated: the file ends inside " + what + " (" + std::to_string(bytes) + " bytes at byte " +
         std::to_string(offset()) + ", only " + std::to_string(remaining()) + " left)");
  auto* out = static_cast<char*>(data);
  const std::size_t buffered = std::min(bytes, mBuffer.size() - mAt);
  if (buffered) std::memcpy(out, mBuffer.data() + mAt, buffered);
  mAt += buffered;
  if (buffered == bytes) return;
  const std::uint64_t start = offset();
  const std::size_t rest = bytes - buffered;
  if (rest < mCapacity / 2) {
    fill(rest);
    if (mBuffer.size() - mAt < rest) fail("the file shrank while reading " + what);
    std::memcpy(out + buffered, mBuffer.data() + mAt, rest);
    mAt += rest;
    return;
  }
  if (mFile->readAt(start, out + buffered, rest) != rest) fail("the file shrank while reading " + what);
  mBuffer.clear();
  mBufferStart = start + rest;
  mAt = 0;
}

std::string_view FileCursor::word(std::size_t maxLength, std::string_view what) {
  for (;;) {
    auto w = window(std::min(mCapacity, maxLength + 1));
    std::size_t i = 0;
    while (i < w.size() && isSpaceByte(w[i])) ++i;
    advance(i);
    if (i < w.size()) break;
    if (windowAtEnd()) return {};
  }
  return wordOnLine(maxLength, what);
}

std::string_view FileCursor::wordOnLine(std::size_t maxLength, std::string_view what) {
  for (;;) {
    auto w = window(std::min(mCapacity, maxLength + 1));
    std::size_t i = 0;
    while (i < w.size() && isBlankByte(w[i])) ++i;
    advance(i);
    if (i < w.size()) break;
    if (windowAtEnd()) return {};
  }
  auto w = window(std::min(mCapacity, maxLength + 1));
  if (w.empty() || w[0] == '\n') return {};
  std::size_t length = 0;
  while (length < w.size() && !isSpaceByte(w[length])) ++length;
  if (length > maxLength)
    fail("a word longer than " + std::to_string(maxLength) + " bytes at byte " + std::to_string(offset()) + " in " +
         std::string(what));
  if (length == w.size())  // windowAtEnd(): nothing follows the word
    fail("truncated: the file ends inside " + std::string(what) + " at byte " + std::to_string(offset() + length));
  std::string_view result(w.data(), length);
  advance(length);
  return result;
}

std::string_view FileCursor::line(std::size_t maxLength, std::string_view what) {
  auto w = window(std::min(mCapacity, maxLength + 2));
  const auto* newline = w.empty() ? nullptr : static_cast<const char*>(std::memchr(w.data(), '\n', w.size()));
  if (!newline) {
    if (w.size() > maxLength)
      fail(std::string(what) + " at byte " + std::to_string(offset()) + " is longer than " + std::to_string(maxLength) +
           " bytes");
    fail("truncated: the file ends inside " + std::string(what) + " (at byte " + std::to_string(offset() + w.size()) +
         ", no line break)");
  }
  std::size_t length = std::size_t(newline - w.data());
  if (length > maxLength)
    fail(std::string(what) + " at byte " + std::to_string(offset()) + " is longer than " + std::to_string(maxLength) +
         " bytes");
  std::string_view result(w.data(), length);
  if (!result.empty() && result.back() == '\r') result.remove_suffix(1);
  advance(length + 1);
  return result;
}

void FileCursor::endLine(std::string_view what) {
  for (;;) {
    auto w = window(256);
    std::size_t i = 0;
    while (i < w.size() && isBlankByte(w[i])) ++i;
    advance(i);
    if (i < w.size()) {
      if (w[i] == '\n') {
        advance(1);
        return;
      }
      std::size_t length = 0;
      while (i + length < w.size() && length < 40 && !isSpaceByte(w[i + length])) ++length;
      fail("unexpected '" + std::string(w.data() + i, length) + "' at byte " + std::to_string(offset()) + " after " +
           std::string(what) + " (expected the end of the line)");
    }
    if (windowAtEnd())
      fail("truncated: the file ends after " + std::string(what) + " (byte " + std::to_string(offset()) + ")");
  }
}

template <class Visit>
void FileCursor::scanWords(std::uint64_t count, bool endTerminates, std::string_view what, Visit&& visit) {
  std::uint64_t done = 0;
  while (done < count) {
    auto w = window(kMaxNumberBytes + 1);
    const char* const begin = w.data();
    const char* const end = begin + w.size();
    const bool last = windowAtEnd();
    const char* p = begin;
    const char* consumed = begin;
    while (done < count) {
      while (p < end && isSpaceByte(*p)) ++p;
      consumed = p;
      if (p == end) break;
      const char* start = p;
      while (p < end && !isSpaceByte(*p)) ++p;
      if (p == end && !(last && endTerminates)) {
        if (last)
          fail("truncated: the file ends inside value " + std::to_string(done) + " of " + std::to_string(count) +
               " of " + std::string(what) + " (byte " + std::to_string(mBufferStart + mAt + (p - begin)) +
               ", no line break after it)");
        p = start;
        break;
      }
      visit(done, std::string_view(start, std::size_t(p - start)), mBufferStart + mAt + std::uint64_t(start - begin));
      ++done;
      consumed = p;
    }
    advance(std::size_t(consumed - begin));
    if (done < count) {
      if (consumed == end && last)
        fail("truncated: " + std::string(what) + " ends after " + std::to_string(done) + " of " +
             std::to_string(count) + " values (byte " + std::to_string(offset()) + ")");
      if (std::size_t(end - consumed) > kMaxNumberBytes)
        fail("a value longer than " + std::to_string(kMaxNumberBytes) + " bytes at byte " + std::to_string(offset()) +
             " in " + std::string(what));
    }
  }
}

void FileCursor::skipWords(std::uint64_t count, bool endTerminates, std::string_view what) {
  scanWords(count, endTerminates, what, [](std::uint64_t, std::string_view, std::uint64_t) {});
}

void FileCursor::parseNumbers(float* out, std::size_t count, ValueType type, bool endTerminates,
                              std::string_view what) {
  scanWords(count, endTerminates, what, [&](std::uint64_t i, std::string_view text, std::uint64_t at) {
    if (!parseNumber(text, type, out[i]))
      fail("malformed number '" + std::string(text.substr(0, 40)) + "' at byte " + std::to_string(at) + " (value " +
           std::to_string(i) + " of " + std::to_string(count) + " of " + std::string(what) + ")");
  });
}

}  // namespace flipscope::detail
