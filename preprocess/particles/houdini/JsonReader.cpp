// JsonReader: what both encodings share (dispatch, walking values, number arrays). The
// encodings themselves: BinaryJson.cpp and AsciiJson.cpp.
#include "preprocess/particles/houdini/JsonReader.h"

#include "core/Error.h"

namespace flipscope::detail::houdini {

const char* tokenKindName(TokenKind kind) {
  switch (kind) {
    case TokenKind::Null: return "null";
    case TokenKind::Bool: return "a boolean";
    case TokenKind::Integer: return "an integer";
    case TokenKind::Real: return "a number";
    case TokenKind::String: return "a string";
    case TokenKind::ArrayBegin: return "an array";
    case TokenKind::ArrayEnd: return "the end of an array";
    case TokenKind::MapBegin: return "a map";
    case TokenKind::MapEnd: return "the end of a map";
    case TokenKind::UniformArray: return "a uniform array";
  }
  return "a token";
}

JsonReader::JsonReader(InputFile& file, JsonEncoding encoding, std::uint64_t offset, std::size_t bufferBytes)
    : mIn(file, bufferBytes), mEncoding(encoding) {
  mIn.seek(offset);
}

void JsonReader::fail(std::uint64_t offset, const std::string& message) const {
  throw FileError(path(), std::string(mEncoding == JsonEncoding::Binary ? "binary" : "ASCII") + " JSON at byte " +
                              std::to_string(offset) + ": " + message);
}

void JsonReader::truncated(const std::string& what) const {
  throw FileError(path(), "truncated: the file ends inside " + what + " (at byte " + std::to_string(mIn.offset()) +
                              ", file size " + std::to_string(mIn.fileSize()) + ")");
}

void JsonReader::next(Token& token, bool keepText) {
  token.text.clear();
  token.integral = false;
  if (mEncoding == JsonEncoding::Binary)
    nextBinary(token, keepText);
  else
    nextAscii(token, keepText);
}

TokenKind JsonReader::peek() { return mEncoding == JsonEncoding::Binary ? peekBinary() : peekAscii(); }

bool JsonReader::atEnd() {
  if (mEncoding == JsonEncoding::Binary)
    skipBinaryPrefix();
  else
    skipAsciiSpace();
  return mIn.atEnd();
}

void JsonReader::skipValue() {
  std::vector<TokenKind> open;
  Token token;
  do {
    const std::uint64_t at = offset();
    next(token, false);
    switch (token.kind) {
      case TokenKind::ArrayBegin:
      case TokenKind::MapBegin:
        if (open.size() == kMaxDepth) fail(at, "values nested deeper than " + std::to_string(kMaxDepth));
        open.push_back(token.kind == TokenKind::ArrayBegin ? TokenKind::ArrayEnd : TokenKind::MapEnd);
        break;
      case TokenKind::ArrayEnd:
      case TokenKind::MapEnd:
        if (open.empty() || open.back() != token.kind)
          fail(at, std::string("unexpected ") + tokenKindName(token.kind) +
                       (open.empty() ? "" : std::string(" (expected ") + tokenKindName(open.back()) + ")"));
        open.pop_back();
        break;
      case TokenKind::UniformArray:
        skipUniform(token.elementType, token.count, at);
        break;
      default:
        break;
    }
  } while (!open.empty());
}

std::string JsonReader::readString(const std::string& what) {
  Token token;
  const std::uint64_t at = offset();
  next(token, true);
  if (token.kind != TokenKind::String) fail(at, what + ": expected a string, found " + tokenKindName(token.kind));
  return std::move(token.text);
}

std::int64_t JsonReader::readInteger(const std::string& what) {
  Token token;
  const std::uint64_t at = offset();
  next(token, false);
  if (token.kind != TokenKind::Integer) fail(at, what + ": expected an integer, found " + tokenKindName(token.kind));
  return token.integer;
}

bool JsonReader::readBool(const std::string& what) {
  Token token;
  const std::uint64_t at = offset();
  next(token, false);
  if (token.kind == TokenKind::Bool || (token.kind == TokenKind::Integer && (token.integer == 0 || token.integer == 1)))
    return token.integer != 0;
  fail(at, what + ": expected a boolean, found " + tokenKindName(token.kind));
}

void JsonReader::beginArray(const std::string& what) {
  Token token;
  const std::uint64_t at = offset();
  next(token, false);
  if (token.kind != TokenKind::ArrayBegin) fail(at, what + ": expected an array, found " + tokenKindName(token.kind));
}

bool JsonReader::endOfArray() {
  if (peek() != TokenKind::ArrayEnd) return false;
  Token token;
  next(token, false);
  return true;
}

NumberArray JsonReader::beginNumbers(const std::string& what) {
  Token token;
  NumberArray array;
  array.offset = offset();
  next(token, false);
  if (token.kind == TokenKind::ArrayBegin) return array;
  if (token.kind != TokenKind::UniformArray)
    fail(array.offset, what + ": expected an array of numbers, found " + tokenKindName(token.kind));
  if (token.elementType == jid::kString || token.elementType == jid::kTokenRef)
    fail(array.offset, what + ": expected an array of numbers, found a uniform array of strings");
  array.uniform = true;
  array.elementType = token.elementType;
  array.remaining = token.count;
  return array;
}

void JsonReader::readNumbers(NumberArray& array, float* out, std::size_t n, const std::string& what) {
  if (array.uniform) {
    if (n > array.remaining)
      fail(array.offset, what + ": the array ends " + std::to_string(array.remaining) +
                             " numbers early (its uniform array is too short)");
    readUniformNumbers(array, out, n, what);
    array.remaining -= n;
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (mEncoding == JsonEncoding::Binary) {
      skipBinaryPrefix();
      if (!mIn.ensure(1)) truncated(what);
      const std::uint8_t b = std::uint8_t(mIn.data()[0]);
      const std::uint64_t at = offset();
      auto load = [&](auto value) {
        if (!mIn.ensure(1 + sizeof value)) truncated(what);
        std::memcpy(&value, mIn.data() + 1, sizeof value);
        mIn.advance(1 + sizeof value);
        return value;
      };
      switch (b) {
        case jid::kReal32: out[i] = load(float()); break;
        case jid::kReal64: out[i] = float(load(double())); break;
        case jid::kInt8: out[i] = float(load(std::int8_t())); break;
        case jid::kInt16: out[i] = float(load(std::int16_t())); break;
        case jid::kInt32: out[i] = float(load(std::int32_t())); break;
        case jid::kInt64: out[i] = float(load(std::int64_t())); break;
        case jid::kUInt8: out[i] = float(load(std::uint8_t())); break;
        case jid::kUInt16: out[i] = float(load(std::uint16_t())); break;
        case jid::kReal16: out[i] = halfToFloat(load(std::uint16_t())); break;
        case 0x5d:
          fail(at, what + ": the array ends " + std::to_string(n - i) + " numbers early");
        default: {
          Token token;
          next(token, false);
          fail(at, what + ": expected a number, found " + tokenKindName(token.kind));
        }
      }
    } else {
      skipAsciiSpace();
      const std::uint64_t at = offset();
      if (!mIn.ensure(1)) truncated(what);
      if (char(mIn.data()[0]) == ']') fail(at, what + ": the array ends " + std::to_string(n - i) + " numbers early");
      if (!readAsciiNumber(out + i, nullptr)) {
        Token token;
        next(token, false);
        fail(at, what + ": expected a number, found " + tokenKindName(token.kind));
      }
    }
  }
}

std::uint64_t JsonReader::skipNumbers(NumberArray& array, const std::string& what) {
  if (array.uniform) {
    const std::uint64_t count = array.remaining;
    if (array.elementType == jid::kBool) {
      const std::uint64_t words = count > std::uint64_t(array.bitsLeft) ? (count - array.bitsLeft + 31) / 32 : 0;
      if (!mIn.skip(words * 4)) truncated(what);
      array.bitsLeft = 0;
    } else {
      skipUniform(array.elementType, count, array.offset);
    }
    array.remaining = 0;
    return count;
  }
  std::uint64_t count = 0;
  if (mEncoding == JsonEncoding::Ascii) {
    for (;;) {
      skipAsciiSpace();
      if (!mIn.ensure(1)) truncated(what);
      if (char(mIn.data()[0]) == ']') {
        mIn.advance(1);
        return count;
      }
      const std::uint64_t at = offset();
      if (!skipAsciiNumber()) {
        Token token;
        next(token, false);
        fail(at, what + ": expected a number, found " + tokenKindName(token.kind));
      }
      ++count;
    }
  }
  float scratch[1];
  for (;;) {
    if (peek() == TokenKind::ArrayEnd) {
      Token token;
      next(token, false);
      return count;
    }
    readNumbers(array, scratch, 1, what);
    ++count;
  }
}

void JsonReader::endNumbers(NumberArray& array, const std::string& what) {
  if (array.uniform) {
    if (array.remaining != 0)
      fail(array.offset, what + ": the array holds " + std::to_string(array.remaining) + " numbers more than expected");
    return;
  }
  const std::uint64_t at = offset();
  Token token;
  next(token, false);
  if (token.kind != TokenKind::ArrayEnd)
    fail(at, what + ": the array holds more numbers than expected (found " + tokenKindName(token.kind) +
                 " where it should end)");
}

std::vector<bool> JsonReader::readBools(const std::string& what) {
  std::vector<bool> flags;
  Token token;
  const std::uint64_t at = offset();
  next(token, false);
  if (token.kind == TokenKind::UniformArray) {
    if (token.elementType == jid::kString || token.elementType == jid::kTokenRef)
      fail(at, what + ": expected booleans, found a uniform array of strings");
    NumberArray array{true, token.elementType, token.count, 0, 0, at};
    float values[256];
    for (std::uint64_t left = token.count; left > 0;) {
      const std::size_t n = std::size_t(std::min<std::uint64_t>(left, 256));
      readNumbers(array, values, n, what);
      for (std::size_t i = 0; i < n; ++i) flags.push_back(values[i] != 0);
      left -= n;
    }
    return flags;
  }
  if (token.kind != TokenKind::ArrayBegin) fail(at, what + ": expected an array of booleans, found " + tokenKindName(token.kind));
  for (;;) {
    const std::uint64_t elementAt = offset();
    next(token, false);
    if (token.kind == TokenKind::ArrayEnd) return flags;
    if (token.kind != TokenKind::Bool && token.kind != TokenKind::Integer)
      fail(elementAt, what + ": expected a boolean, found " + tokenKindName(token.kind));
    flags.push_back(token.integer != 0);
  }
}

}  // namespace flipscope::detail::houdini
