// Base64 (RFC 4648, the standard alphabet) decoded as a stream from a FileCursor, for formats
// that embed binary data in text (VTK XML). Whitespace is skipped, and '=' padding may close a
// group anywhere, not only at the end: VTK encodes an array's header apart from its data, so
// the text reads "XXXXXX==XXXX...".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "preprocess/particles/FileCursor.h"

namespace flipscope::detail {

class Base64Reader {
 public:
  /// Decodes the text of `text` (which must outlive the reader) from its offset on.
  explicit Base64Reader(FileCursor& text) : mText(&text) {}
  /// Decodes exactly `bytes` bytes into `out`; throws FileError naming `what` when the text
  /// ends first or holds a byte that is not base64.
  void read(std::byte* out, std::size_t bytes, const std::string& what);
  /// At most how many more bytes the text can decode to.
  std::uint64_t maxRemaining() const {
    return mText->remaining() / 4 * 3 + 3 + std::uint64_t(mPendingSize - mPendingAt);
  }

 private:
  FileCursor* mText;
  std::uint8_t mQuad[4] = {};
  int mQuadSize = 0;
  int mPadLeft = 0;  ///< '=' still allowed after a padded group
  std::byte mPending[3] = {};
  int mPendingSize = 0, mPendingAt = 0;
};

}  // namespace flipscope::detail
