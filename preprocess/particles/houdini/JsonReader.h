// JsonReader: the token stream of Houdini's JSON geometry, in either of its two encodings:
//  - binary JSON (.bgeo, UT_JSONDefines.h in the HDK): after the magic 0x7f "NSJb", one byte
//    a token, little-endian values; strings may be defined once in a table (token definitions)
//    and then referred to by id; arrays of one scalar type may be "uniform" (type, count, then
//    the raw values; booleans packed 32 to a little-endian word). Lengths and ids are one byte
//    below 0xf1, else 0xf2 / 0xf4 / 0xf8 followed by a 16 / 32 / 64-bit count.
//  - ASCII JSON (.geo): plain JSON text (nan and inf are accepted as numbers).
// The walker (GeoScan.cpp, AttributeCursor.cpp) reads both through the same calls; bulk number
// arrays are decoded in tight loops (readNumbers), never a virtual call a value. Every token
// is checked against the bytes left: malformed or truncated input throws FileError naming the
// byte offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/houdini/ByteCursor.h"

namespace flipscope::detail::houdini {

enum class JsonEncoding : std::uint8_t { Binary, Ascii };

/// The first bytes of a binary JSON file: UT_JID_MAGIC then "NSJb" (little-endian).
inline constexpr unsigned char kBinaryMagic[5] = {0x7f, 'N', 'S', 'J', 'b'};
/// The magic of a byte-swapped (big-endian) binary JSON file.
inline constexpr unsigned char kSwappedMagic[5] = {0x7f, 'b', 'J', 'S', 'N'};

enum class TokenKind : std::uint8_t { Null, Bool, Integer, Real, String, ArrayBegin, ArrayEnd, MapBegin, MapEnd, UniformArray };

/// Element types of binary uniform arrays (the UT_JID byte).
namespace jid {
inline constexpr std::uint8_t kBool = 0x10, kInt8 = 0x11, kInt16 = 0x12, kInt32 = 0x13, kInt64 = 0x14, kReal16 = 0x18,
                              kReal32 = 0x19, kReal64 = 0x1a, kUInt8 = 0x21, kUInt16 = 0x22, kString = 0x27,
                              kTokenRef = 0x26;
}

struct Token {
  TokenKind kind = TokenKind::Null;
  std::uint64_t offset = 0;  ///< where the token starts
  bool integral = false;     ///< Integer, or Bool
  std::int64_t integer = 0;  ///< Integer (and Bool: 0 or 1)
  double real = 0;           ///< Integer and Real
  std::string text;          ///< String, when asked for
  std::uint8_t elementType = 0;  ///< UniformArray: the jid of its elements
  std::uint64_t count = 0;       ///< UniformArray: its element count (its values follow)
};

/// An IEEE 754 half-precision value (binary real16) as float.
inline float halfToFloat(std::uint16_t bits) {
  const std::uint32_t sign = std::uint32_t(bits & 0x8000u) << 16;
  const std::uint32_t exponent = (bits >> 10) & 0x1fu;
  std::uint32_t mantissa = bits & 0x3ffu;
  std::uint32_t result;
  if (exponent == 0x1f) {
    result = sign | 0x7f800000u | (mantissa << 13);  // inf, nan
  } else if (exponent != 0) {
    result = sign | ((exponent + 112) << 23) | (mantissa << 13);
  } else if (mantissa == 0) {
    result = sign;
  } else {  // subnormal: normalise
    int shift = 0;
    while (!(mantissa & 0x400u)) {
      mantissa <<= 1;
      ++shift;
    }
    result = sign | (std::uint32_t(113 - shift) << 23) | ((mantissa & 0x3ffu) << 13);
  }
  float value;
  std::memcpy(&value, &result, sizeof value);
  return value;
}

/// "a string", "an array", ... for messages.
const char* tokenKindName(TokenKind kind);

/// The state of a number array being read: after its '[' or uniform-array header.
struct NumberArray {
  bool uniform = false;
  std::uint8_t elementType = 0;  ///< uniform: jid of the elements
  std::uint64_t remaining = 0;   ///< uniform: elements left
  std::uint32_t bitWord = 0;     ///< uniform booleans: the current 32-bit word ...
  int bitsLeft = 0;              ///< ... and how many of its bits are unread
  std::uint64_t offset = 0;      ///< where the array starts, for messages
};

class JsonReader {
 public:
  /// Reads `file` (which must outlive the reader) from `offset`: just after the magic of a
  /// binary file, or anywhere in a text file.
  JsonReader(InputFile& file, JsonEncoding encoding, std::uint64_t offset, std::size_t bufferBytes);

  JsonEncoding encoding() const { return mEncoding; }
  const std::filesystem::path& path() const { return mIn.path(); }
  /// Offset of the next byte (after peek(): of the next token).
  std::uint64_t offset() const { return mIn.offset(); }
  void seek(std::uint64_t offset) { mIn.seek(offset); }

  /// Reads the next token. String text is kept only if `keepText`. A uniform array's values
  /// are left for readNumbers() / skipNumbers() / readBools() / skipUniform().
  void next(Token& token, bool keepText = true);
  /// The kind of the next token, not consumed (binary token definitions before it are read).
  TokenKind peek();
  /// Whether only whitespace (text) or nothing (binary) is left.
  bool atEnd();

  // Walking values.
  /// Skips one whole value (nested arrays and maps included, depth at most kMaxDepth).
  void skipValue();
  /// The next token must be a string (or an integer, for readInteger): its value.
  std::string readString(const std::string& what);
  std::int64_t readInteger(const std::string& what);
  bool readBool(const std::string& what);
  /// Reads an ordered map: a map {"key": value, ...} or Houdini's array of alternating keys and
  /// values ["key", value, ...]; calls `onKey(key)` for each key, which must consume the value.
  template <class OnKey>
  void readEntries(const std::string& what, OnKey&& onKey);
  /// The next token must begin an array ('[' of any encoding): consumes it.
  void beginArray(const std::string& what);
  /// Whether the array being read ends here; if so, consumes its ']'.
  bool endOfArray();

  // Number arrays ('[' numbers ']', or a binary uniform array of a numeric type).
  /// Begins a number array: the next token must be one.
  NumberArray beginNumbers(const std::string& what);
  /// Reads exactly `n` numbers of `array` as float; throws if it ends first or holds
  /// something else.
  void readNumbers(NumberArray& array, float* out, std::size_t n, const std::string& what);
  /// Consumes the rest of `array`, checking that it holds numbers only; returns their count.
  std::uint64_t skipNumbers(NumberArray& array, const std::string& what);
  /// Expects `array` to end here.
  void endNumbers(NumberArray& array, const std::string& what);
  /// Reads a whole array of booleans ('[' true/false/0/1 ']' or a uniform array).
  std::vector<bool> readBools(const std::string& what);

  static constexpr int kMaxDepth = 1024;
  static constexpr std::size_t kMaxStringBytes = std::size_t(1) << 24;  ///< one string
  static constexpr std::size_t kMaxTokenTableBytes = std::size_t(1) << 26;  ///< all binary token definitions

  /// FileError "<what> at byte <offset>: <message>".
  [[noreturn]] void fail(std::uint64_t offset, const std::string& message) const;
  [[noreturn]] void truncated(const std::string& what) const;

 private:
  // Binary (BinaryJson.cpp).
  void nextBinary(Token& token, bool keepText);
  std::uint64_t readLength(const char* what);
  void readBinaryString(std::string* out, const char* what);
  void skipUniform(std::uint8_t type, std::uint64_t count, std::uint64_t at);
  std::size_t readUniformNumbers(NumberArray& array, float* out, std::size_t n, const std::string& what);
  void skipBinaryPrefix();  ///< token definitions and separators before the next token
  TokenKind peekBinary();
  TokenKind peekAscii();
  // Text (AsciiJson.cpp).
  void nextAscii(Token& token, bool keepText);
  void skipAsciiSpace();
  void readAsciiString(std::string* out);
  /// Reads a number's text at the offset; false if the next token is no number.
  bool readAsciiNumber(float* asFloat, Token* token);
  /// Skips what reads as a number's text, without converting it (the first pass: the values
  /// are converted, and checked, when read); false if the next token is no number.
  bool skipAsciiNumber();

  ByteCursor mIn;
  JsonEncoding mEncoding;
  std::unordered_map<std::uint64_t, std::string> mTokens;  ///< binary token definitions by id
  std::size_t mTokenBytes = 0;
  std::string mScratch;
};

template <class OnKey>
void JsonReader::readEntries(const std::string& what, OnKey&& onKey) {
  Token token;
  const std::uint64_t at = offset();
  next(token, false);
  TokenKind end;
  if (token.kind == TokenKind::ArrayBegin)
    end = TokenKind::ArrayEnd;
  else if (token.kind == TokenKind::MapBegin)
    end = TokenKind::MapEnd;
  else
    fail(at, what + ": expected an array or a map, found " + tokenKindName(token.kind));
  for (;;) {
    if (peek() == end) {
      next(token, false);
      return;
    }
    const std::uint64_t keyAt = offset();
    next(token, true);
    if (token.kind != TokenKind::String)
      fail(keyAt, what + ": expected a key (a string), found " + tokenKindName(token.kind));
    if (peek() == end) fail(offset(), what + ": key '" + token.text + "' has no value");
    onKey(token.text);
  }
}

}  // namespace flipscope::detail::houdini
