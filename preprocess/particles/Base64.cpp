#include "preprocess/particles/Base64.h"

#include <array>

namespace flipscope::detail {
namespace {

constexpr std::uint8_t kSpace = 64, kPad = 65, kInvalid = 255;

constexpr std::array<std::uint8_t, 256> makeTable() {
  std::array<std::uint8_t, 256> table{};
  for (auto& entry : table) entry = kInvalid;
  constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (int i = 0; i < 64; ++i) table[static_cast<unsigned char>(kAlphabet[i])] = std::uint8_t(i);
  for (char c : {' ', '\t', '\n', '\r', '\v', '\f'}) table[static_cast<unsigned char>(c)] = kSpace;
  table['='] = kPad;
  return table;
}
constexpr std::array<std::uint8_t, 256> kTable = makeTable();

std::string printable(unsigned char c) {
  if (c >= 0x20 && c < 0x7f) return std::string(1, char(c));
  static constexpr char kHex[] = "0123456789abcdef";
  return std::string("\\x") + kHex[c >> 4] + kHex[c & 15];
}

}  // namespace

void Base64Reader::read(std::byte* out, std::size_t bytes, const std::string& what) {
  std::size_t done = 0;
  while (done < bytes) {
    if (mPendingAt < mPendingSize) {
      while (mPendingAt < mPendingSize && done < bytes) out[done++] = mPending[mPendingAt++];
      continue;
    }
    auto w = mText->window(4096);
    if (w.empty())
      mText->fail("truncated: the base64 text of " + what + " ends after " + std::to_string(done) + " of " +
                  std::to_string(bytes) + " bytes (byte " + std::to_string(mText->offset()) + ")");
    const auto* p = reinterpret_cast<const unsigned char*>(w.data());
    const auto* const end = p + w.size();
    const auto* const begin = p;
    auto offsetOf = [&](const unsigned char* at) { return mText->offset() + std::uint64_t(at - begin); };
    while (p < end && done < bytes) {
      // Fast path: whole groups of four alphabet characters.
      if (mQuadSize == 0)
        while (end - p >= 4 && bytes - done >= 3) {
          const std::uint32_t a = kTable[p[0]], b = kTable[p[1]], c = kTable[p[2]], d = kTable[p[3]];
          if ((a | b | c | d) >= 64) break;
          const std::uint32_t v = a << 18 | b << 12 | c << 6 | d;
          out[done] = std::byte(v >> 16);
          out[done + 1] = std::byte(v >> 8);
          out[done + 2] = std::byte(v);
          done += 3;
          p += 4;
          mPadLeft = 0;
        }
      if (p == end || done == bytes) break;
      // One character: whitespace, padding, or part of a group that crosses the window or the end.
      const std::uint8_t v = kTable[*p];
      if (v < 64) {
        mPadLeft = 0;
        mQuad[mQuadSize++] = v;
        if (mQuadSize == 4) {
          const std::uint32_t bits = std::uint32_t(mQuad[0]) << 18 | mQuad[1] << 12 | mQuad[2] << 6 | mQuad[3];
          mPending[0] = std::byte(bits >> 16);
          mPending[1] = std::byte(bits >> 8);
          mPending[2] = std::byte(bits);
          mPendingSize = 3;
          mPendingAt = 0;
          mQuadSize = 0;
        }
      } else if (v == kPad) {
        if (mQuadSize >= 2) {
          const std::uint32_t bits =
              std::uint32_t(mQuad[0]) << 18 | mQuad[1] << 12 | (mQuadSize == 3 ? mQuad[2] << 6 : 0);
          mPending[0] = std::byte(bits >> 16);
          mPending[1] = std::byte(bits >> 8);
          mPendingSize = mQuadSize - 1;
          mPendingAt = 0;
          mPadLeft = 3 - mQuadSize;
          mQuadSize = 0;
        } else if (mQuadSize == 0 && mPadLeft > 0) {
          --mPadLeft;
        } else {
          mText->fail("malformed base64 in " + what + ": '=' at byte " + std::to_string(offsetOf(p)) +
                      " inside a group");
        }
      } else if (v != kSpace) {
        mText->fail("malformed base64 in " + what + ": byte " + std::to_string(offsetOf(p)) + " is '" + printable(*p) +
                    "', not a base64 character");
      }
      ++p;
      while (mPendingAt < mPendingSize && done < bytes) out[done++] = mPending[mPendingAt++];
    }
    mText->advance(std::size_t(p - begin));
  }
}

}  // namespace flipscope::detail
