// Houdini's ASCII geometry (.geo): plain JSON text, the token decoder of JsonReader. Commas and
// colons are read as white space (the walker checks the structure); nan and inf (any case, as
// std::from_chars reads them) are numbers.
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/houdini/JsonReader.h"

namespace flipscope::detail::houdini {
namespace {

constexpr std::size_t kMaxNumberChars = 64;

struct CharClasses {
  bool space[256] = {}, delimiter[256] = {};
  constexpr CharClasses() {
    for (unsigned char c : {' ', '\t', '\n', '\r', ',', ':'}) space[c] = delimiter[c] = true;
    for (unsigned char c : {']', '}', '[', '{', '"'}) delimiter[c] = true;
  }
};
constexpr CharClasses kClasses;
bool isSpace(char c) { return kClasses.space[static_cast<unsigned char>(c)]; }
bool isDelimiter(char c) { return kClasses.delimiter[static_cast<unsigned char>(c)]; }

/// The length of the text from `p` (of `n` bytes) to the first delimiter, or `n`.
std::size_t undelimited(const char* p, std::size_t n, std::size_t from) {
  while (from < n && !isDelimiter(p[from])) ++from;
  return from;
}

/// A finite number too large or small for T: +-inf or +-0 by the sign of its exponent.
double outOfRange(std::string_view text) {
  const bool negative = !text.empty() && text[0] == '-';
  const bool tiny = text.find("e-") != std::string_view::npos || text.find("E-") != std::string_view::npos;
  const double magnitude = tiny ? 0.0 : HUGE_VAL;
  return negative ? -magnitude : magnitude;
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void appendUtf8(std::string& out, std::uint32_t code) {
  if (code < 0x80) {
    out += char(code);
  } else if (code < 0x800) {
    out += char(0xc0 | (code >> 6));
    out += char(0x80 | (code & 0x3f));
  } else if (code < 0x10000) {
    out += char(0xe0 | (code >> 12));
    out += char(0x80 | ((code >> 6) & 0x3f));
    out += char(0x80 | (code & 0x3f));
  } else {
    out += char(0xf0 | (code >> 18));
    out += char(0x80 | ((code >> 12) & 0x3f));
    out += char(0x80 | ((code >> 6) & 0x3f));
    out += char(0x80 | (code & 0x3f));
  }
}

}  // namespace

void JsonReader::skipAsciiSpace() {
  while (mIn.ensure(1)) {
    const char* p = reinterpret_cast<const char*>(mIn.data());
    const std::size_t n = mIn.available();
    std::size_t i = 0;
    while (i < n && isSpace(p[i])) ++i;
    mIn.advance(i);
    if (i < n) return;
  }
}

TokenKind JsonReader::peekAscii() {
  skipAsciiSpace();
  if (!mIn.ensure(1)) truncated("the next value");
  switch (char(mIn.data()[0])) {
    case '[': return TokenKind::ArrayBegin;
    case ']': return TokenKind::ArrayEnd;
    case '{': return TokenKind::MapBegin;
    case '}': return TokenKind::MapEnd;
    case '"': return TokenKind::String;
    case 't':
    case 'f': return TokenKind::Bool;
    case 'n': return mIn.ensure(2) && char(mIn.data()[1]) == 'u' ? TokenKind::Null : TokenKind::Real;
    default: return TokenKind::Real;
  }
}

bool JsonReader::readAsciiNumber(float* asFloat, Token* token) {
  std::size_t length = 0;
  for (;;) {  // the text up to a delimiter or the end of the file, in the buffer
    length = undelimited(reinterpret_cast<const char*>(mIn.data()), mIn.available(), length);
    if (length > kMaxNumberChars)
      fail(offset(), "a number longer than " + std::to_string(kMaxNumberChars) + " characters");
    if (length < mIn.available() || !mIn.ensure(length + 1)) break;
  }
  if (length == 0) return false;
  const char* text = reinterpret_cast<const char*>(mIn.data());
  const char* end = text + length;
  const std::string_view view(text, length);
  auto malformed = [&]() { fail(offset(), "malformed number '" + std::string(view) + "'"); };
  if (asFloat) {  // as double, then rounded to float: what a binary real64 token gives
    double value = 0;
    auto [ptr, ec] = std::from_chars(text, end, value);
    if (ptr != end || (ec != std::errc() && ec != std::errc::result_out_of_range)) malformed();
    if (ec == std::errc::result_out_of_range) value = outOfRange(view);
    *asFloat = float(value);
  } else {
    std::size_t digits = text[0] == '-' ? 1 : 0;
    bool integral = digits < length;
    for (std::size_t i = digits; i < length; ++i) integral = integral && text[i] >= '0' && text[i] <= '9';
    std::int64_t integer = 0;
    if (integral) {
      auto [ptr, ec] = std::from_chars(text, end, integer);
      integral = ec == std::errc() && ptr == end;
    }
    if (integral) {
      token->kind = TokenKind::Integer;
      token->integral = true;
      token->integer = integer;
      token->real = double(integer);
    } else {
      double value = 0;
      auto [ptr, ec] = std::from_chars(text, end, value);
      if (ptr != end || (ec != std::errc() && ec != std::errc::result_out_of_range)) malformed();
      token->kind = TokenKind::Real;
      token->real = ec == std::errc() ? value : outOfRange(view);
    }
  }
  mIn.advance(length);
  return true;
}

bool JsonReader::skipAsciiNumber() {
  if (!mIn.ensure(1)) return false;
  const char first = char(mIn.data()[0]);
  if (!((first >= '0' && first <= '9') || first == '-' || first == 'n' || first == 'N' || first == 'i' || first == 'I'))
    return false;
  std::size_t length = 0;
  for (;;) {
    length = undelimited(reinterpret_cast<const char*>(mIn.data()), mIn.available(), length);
    if (length > kMaxNumberChars)
      fail(offset(), "a number longer than " + std::to_string(kMaxNumberChars) + " characters");
    if (length < mIn.available() || !mIn.ensure(length + 1)) break;
  }
  mIn.advance(length);
  return true;
}

void JsonReader::readAsciiString(std::string* out) {
  const std::uint64_t start = offset() - 1;
  auto append = [&](const char* text, std::size_t n) {
    if (!out) return;
    if (out->size() + n > kMaxStringBytes)
      fail(start, "a string longer than " + std::to_string(kMaxStringBytes >> 20) + " MiB");
    out->append(text, n);
  };
  for (;;) {
    if (!mIn.ensure(1)) truncated("a string (starting at byte " + std::to_string(start) + ")");
    const char* p = reinterpret_cast<const char*>(mIn.data());
    const std::size_t n = mIn.available();
    std::size_t i = 0;
    while (i < n && p[i] != '"' && p[i] != '\\') ++i;
    append(p, i);
    mIn.advance(i);
    if (i == n) continue;
    if (p[i] == '"') {
      mIn.advance(1);
      return;
    }
    if (!mIn.ensure(2)) truncated("a string (starting at byte " + std::to_string(start) + ")");
    const char escape = char(mIn.data()[1]);
    char plain = 0;
    switch (escape) {
      case '"': plain = '"'; break;
      case '\\': plain = '\\'; break;
      case '/': plain = '/'; break;
      case 'b': plain = '\b'; break;
      case 'f': plain = '\f'; break;
      case 'n': plain = '\n'; break;
      case 'r': plain = '\r'; break;
      case 't': plain = '\t'; break;
      case 'u': break;
      default: fail(offset(), std::string("bad escape '\\") + escape + "' in a string");
    }
    if (plain) {
      append(&plain, 1);
      mIn.advance(2);
      continue;
    }
    auto hex4 = [&](std::size_t at) -> std::uint32_t {
      std::uint32_t code = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        const int digit = hexDigit(char(mIn.data()[at + k]));
        if (digit < 0) fail(offset(), "bad \\u escape in a string");
        code = code * 16 + std::uint32_t(digit);
      }
      return code;
    };
    if (!mIn.ensure(6)) truncated("a string (starting at byte " + std::to_string(start) + ")");
    std::uint32_t code = hex4(2);
    std::size_t used = 6;
    if (code >= 0xd800 && code < 0xdc00 && mIn.ensure(12) && char(mIn.data()[6]) == '\\' &&
        char(mIn.data()[7]) == 'u') {
      const std::uint32_t low = hex4(8);
      if (low >= 0xdc00 && low < 0xe000) {
        code = 0x10000 + ((code - 0xd800) << 10) + (low - 0xdc00);
        used = 12;
      }
    }
    if (out) {
      std::string utf8;
      appendUtf8(utf8, code);
      append(utf8.data(), utf8.size());
    }
    mIn.advance(used);
  }
}

void JsonReader::nextAscii(Token& token, bool keepText) {
  skipAsciiSpace();
  token.offset = offset();
  if (!mIn.ensure(1)) truncated("a value");
  const char c = char(mIn.data()[0]);
  auto literal = [&](const char* word) {
    const std::size_t n = std::strlen(word);
    if (!mIn.ensure(n) || std::memcmp(mIn.data(), word, n) != 0) return false;
    if (mIn.ensure(n + 1) && !isDelimiter(char(mIn.data()[n]))) return false;
    mIn.advance(n);
    return true;
  };
  switch (c) {
    case '[': mIn.advance(1); token.kind = TokenKind::ArrayBegin; return;
    case ']': mIn.advance(1); token.kind = TokenKind::ArrayEnd; return;
    case '{': mIn.advance(1); token.kind = TokenKind::MapBegin; return;
    case '}': mIn.advance(1); token.kind = TokenKind::MapEnd; return;
    case '"':
      mIn.advance(1);
      readAsciiString(keepText ? &token.text : nullptr);
      token.kind = TokenKind::String;
      return;
    default: break;
  }
  if (literal("true") || literal("false")) {
    token.kind = TokenKind::Bool;
    token.integral = true;
    token.integer = c == 't';
    return;
  }
  if (literal("null")) {
    token.kind = TokenKind::Null;
    return;
  }
  if (!readAsciiNumber(nullptr, &token)) fail(token.offset, std::string("unexpected character '") + c + "'");
}

}  // namespace flipscope::detail::houdini
