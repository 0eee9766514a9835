// Houdini's binary JSON (UT_JSONDefines.h of the HDK): the token decoder of JsonReader. One
// byte a token (UT_JID), little-endian payloads; see JsonReader.h for the encoding.
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/houdini/JsonReader.h"

namespace flipscope::detail::houdini {
namespace {

constexpr std::uint8_t kNull = 0x00, kMapBegin = 0x7b, kMapEnd = 0x7d, kArrayBegin = 0x5b, kArrayEnd = 0x5d,
                       kFalse = 0x30, kTrue = 0x31, kTokenDef = 0x2b, kTokenUndef = 0x2d, kUniform = 0x40,
                       kKeySeparator = 0x3a, kValueSeparator = 0x2c, kMagic = 0x7f;

/// Bytes a value of a scalar jid; 0 for others.
std::size_t scalarBytes(std::uint8_t type) {
  switch (type) {
    case jid::kInt8:
    case jid::kUInt8: return 1;
    case jid::kInt16:
    case jid::kUInt16:
    case jid::kReal16: return 2;
    case jid::kInt32:
    case jid::kReal32: return 4;
    case jid::kInt64:
    case jid::kReal64: return 8;
    default: return 0;
  }
}

std::string hexByte(std::uint8_t b) {
  static constexpr char kHex[] = "0123456789abcdef";
  return std::string("0x") + kHex[b >> 4] + kHex[b & 15];
}

template <class T>
void convertRun(const std::byte* in, float* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    T value;
    std::memcpy(&value, in + i * sizeof(T), sizeof(T));
    out[i] = float(value);
  }
}

}  // namespace

std::uint64_t JsonReader::readLength(const char* what) {
  if (!mIn.ensure(1)) truncated(what);
  const std::uint8_t b = std::uint8_t(mIn.data()[0]);
  if (b < 0xf1) {
    mIn.advance(1);
    return b;
  }
  std::size_t bytes = b == 0xf2 ? 2 : b == 0xf4 ? 4 : b == 0xf8 ? 8 : 0;
  if (bytes == 0) fail(offset(), std::string("bad length byte ") + hexByte(b) + " in " + what);
  if (!mIn.ensure(1 + bytes)) truncated(what);
  std::uint64_t value = 0;
  std::memcpy(&value, mIn.data() + 1, bytes);  // little-endian
  mIn.advance(1 + bytes);
  return value;
}

void JsonReader::readBinaryString(std::string* out, const char* what) {
  const std::uint64_t at = offset();
  const std::uint64_t length = readLength(what);
  if (length > mIn.remaining()) truncated(std::string(what) + " of " + std::to_string(length) + " bytes");
  if (!out) {
    mIn.skip(length);
    return;
  }
  if (length > kMaxStringBytes) fail(at, std::string(what) + " of " + std::to_string(length) + " bytes: too long");
  mIn.ensure(std::size_t(length));
  out->assign(reinterpret_cast<const char*>(mIn.data()), std::size_t(length));
  mIn.advance(std::size_t(length));
}

void JsonReader::skipBinaryPrefix() {
  while (mIn.ensure(1)) {
    const std::uint8_t b = std::uint8_t(mIn.data()[0]);
    if (b == kKeySeparator || b == kValueSeparator) {
      mIn.advance(1);
    } else if (b == kTokenDef) {
      const std::uint64_t at = offset();
      mIn.advance(1);
      const std::uint64_t id = readLength("a token definition");
      readBinaryString(&mScratch, "a token definition");
      auto [it, inserted] = mTokens.try_emplace(id);
      if (!inserted) mTokenBytes -= it->second.size();
      mTokenBytes += mScratch.size() + 16;
      if (mTokenBytes > kMaxTokenTableBytes)
        fail(at, "the token definitions exceed " + std::to_string(kMaxTokenTableBytes >> 20) + " MiB");
      it->second.swap(mScratch);
    } else if (b == kTokenUndef) {
      mIn.advance(1);
      const std::uint64_t id = readLength("a token removal");
      auto it = mTokens.find(id);
      if (it != mTokens.end()) {
        mTokenBytes -= it->second.size() + 16;
        mTokens.erase(it);
      }
    } else {
      return;
    }
  }
}

TokenKind JsonReader::peekBinary() {
  skipBinaryPrefix();
  if (!mIn.ensure(1)) truncated("the next token");
  const std::uint8_t b = std::uint8_t(mIn.data()[0]);
  switch (b) {
    case kArrayBegin: return TokenKind::ArrayBegin;
    case kArrayEnd: return TokenKind::ArrayEnd;
    case kMapBegin: return TokenKind::MapBegin;
    case kMapEnd: return TokenKind::MapEnd;
    case kUniform: return TokenKind::UniformArray;
    case jid::kString:
    case jid::kTokenRef: return TokenKind::String;
    case kNull: return TokenKind::Null;
    case jid::kBool:
    case kFalse:
    case kTrue: return TokenKind::Bool;
    case jid::kReal16:
    case jid::kReal32:
    case jid::kReal64: return TokenKind::Real;
    default:
      if (scalarBytes(b)) return TokenKind::Integer;
      fail(offset(), "unknown token " + hexByte(b));
  }
}

void JsonReader::nextBinary(Token& token, bool keepText) {
  skipBinaryPrefix();
  token.offset = offset();
  if (!mIn.ensure(1)) truncated("a token");
  const std::uint8_t b = std::uint8_t(mIn.data()[0]);
  auto load = [&](auto value, const char* what) {
    if (!mIn.ensure(1 + sizeof value)) truncated(what);
    std::memcpy(&value, mIn.data() + 1, sizeof value);
    mIn.advance(1 + sizeof value);
    return value;
  };
  auto integer = [&](std::int64_t value) {
    token.kind = TokenKind::Integer;
    token.integral = true;
    token.integer = value;
    token.real = double(value);
  };
  auto real = [&](double value) {
    token.kind = TokenKind::Real;
    token.real = value;
  };
  switch (b) {
    case kNull: mIn.advance(1); token.kind = TokenKind::Null; return;
    case kArrayBegin: mIn.advance(1); token.kind = TokenKind::ArrayBegin; return;
    case kArrayEnd: mIn.advance(1); token.kind = TokenKind::ArrayEnd; return;
    case kMapBegin: mIn.advance(1); token.kind = TokenKind::MapBegin; return;
    case kMapEnd: mIn.advance(1); token.kind = TokenKind::MapEnd; return;
    case kFalse:
    case kTrue:
      mIn.advance(1);
      token.kind = TokenKind::Bool;
      token.integral = true;
      token.integer = b == kTrue;
      return;
    case jid::kBool:
      token.integer = load(std::uint8_t(), "a boolean") != 0;
      token.kind = TokenKind::Bool;
      token.integral = true;
      return;
    case jid::kInt8: integer(load(std::int8_t(), "an int8")); return;
    case jid::kInt16: integer(load(std::int16_t(), "an int16")); return;
    case jid::kInt32: integer(load(std::int32_t(), "an int32")); return;
    case jid::kInt64: integer(load(std::int64_t(), "an int64")); return;
    case jid::kUInt8: integer(load(std::uint8_t(), "a uint8")); return;
    case jid::kUInt16: integer(load(std::uint16_t(), "a uint16")); return;
    case jid::kReal16: real(halfToFloat(load(std::uint16_t(), "a real16"))); return;
    case jid::kReal32: real(load(float(), "a real32")); return;
    case jid::kReal64: real(load(double(), "a real64")); return;
    case jid::kString:
      mIn.advance(1);
      readBinaryString(keepText ? &token.text : nullptr, "a string");
      token.kind = TokenKind::String;
      return;
    case jid::kTokenRef: {
      mIn.advance(1);
      const std::uint64_t id = readLength("a token reference");
      auto it = mTokens.find(id);
      if (it == mTokens.end()) fail(token.offset, "reference to token " + std::to_string(id) + ", which is not defined");
      if (keepText) token.text = it->second;
      token.kind = TokenKind::String;
      return;
    }
    case kUniform: {
      mIn.advance(1);
      if (!mIn.ensure(1)) truncated("a uniform array");
      token.elementType = std::uint8_t(mIn.data()[0]);
      mIn.advance(1);
      token.count = readLength("a uniform array");
      token.kind = TokenKind::UniformArray;
      const std::size_t bytes = scalarBytes(token.elementType);
      const std::uint64_t left = mIn.remaining();
      const char* typeName = nullptr;
      if (bytes) {
        if (token.count > left / bytes) typeName = "values";
      } else if (token.elementType == jid::kBool) {
        if ((token.count + 31) / 32 > left / 4) typeName = "booleans";
      } else if (token.elementType == jid::kString || token.elementType == jid::kTokenRef) {
        if (token.count > left) typeName = "strings";
      } else {
        fail(token.offset, "uniform array of unknown element type " + hexByte(token.elementType));
      }
      if (typeName)
        truncated("a uniform array of " + std::to_string(token.count) + " " + typeName + " (starting at byte " +
                  std::to_string(token.offset) + ")");
      return;
    }
    case kMagic: fail(token.offset, "a second binary JSON magic inside the file");
    default: fail(token.offset, "unknown token " + hexByte(b));
  }
}

void JsonReader::skipUniform(std::uint8_t type, std::uint64_t count, std::uint64_t at) {
  const std::string what = "a uniform array (starting at byte " + std::to_string(at) + ")";
  if (const std::size_t bytes = scalarBytes(type)) {
    if (count > mIn.remaining() / bytes || !mIn.skip(count * bytes)) truncated(what);
  } else if (type == jid::kBool) {
    if ((count + 31) / 32 > mIn.remaining() / 4 || !mIn.skip((count + 31) / 32 * 4)) truncated(what);
  } else if (type == jid::kString) {
    for (std::uint64_t i = 0; i < count; ++i) readBinaryString(nullptr, "a string of a uniform array");
  } else if (type == jid::kTokenRef) {
    for (std::uint64_t i = 0; i < count; ++i) readLength("a token reference of a uniform array");
  } else {
    fail(at, "uniform array of unknown element type " + hexByte(type));
  }
}

std::size_t JsonReader::readUniformNumbers(NumberArray& array, float* out, std::size_t n, const std::string& what) {
  const std::uint8_t type = array.elementType;
  if (type == jid::kBool) {
    for (std::size_t i = 0; i < n; ++i) {
      if (array.bitsLeft == 0) {
        if (!mIn.ensure(4)) truncated(what);
        std::memcpy(&array.bitWord, mIn.data(), 4);
        mIn.advance(4);
        array.bitsLeft = 32;
      }
      out[i] = float(array.bitWord & 1u);
      array.bitWord >>= 1;
      --array.bitsLeft;
    }
    return n;
  }
  const std::size_t bytes = scalarBytes(type);
  if (bytes == 0) fail(array.offset, what + ": expected numbers, found a uniform array of strings");
  if (type == jid::kReal32) {  // the common case: straight into the output
    if (!mIn.read(out, n * 4)) truncated(what);
    return n;
  }
  std::size_t done = 0;
  while (done < n) {
    if (mIn.available() < bytes && !mIn.ensure(bytes)) truncated(what);
    const std::size_t k = std::min(n - done, mIn.available() / bytes);
    const std::byte* in = mIn.data();
    float* dst = out + done;
    switch (type) {
      case jid::kReal32: std::memcpy(dst, in, k * 4); break;
      case jid::kReal64: convertRun<double>(in, dst, k); break;
      case jid::kInt8: convertRun<std::int8_t>(in, dst, k); break;
      case jid::kUInt8: convertRun<std::uint8_t>(in, dst, k); break;
      case jid::kInt16: convertRun<std::int16_t>(in, dst, k); break;
      case jid::kUInt16: convertRun<std::uint16_t>(in, dst, k); break;
      case jid::kInt32: convertRun<std::int32_t>(in, dst, k); break;
      case jid::kInt64: convertRun<std::int64_t>(in, dst, k); break;
      case jid::kReal16:
        for (std::size_t i = 0; i < k; ++i) {
          std::uint16_t bits;
          std::memcpy(&bits, in + 2 * i, 2);
          dst[i] = halfToFloat(bits);
        }
        break;
    }
    mIn.advance(k * bytes);
    done += k;
  }
  return n;
}

}  // namespace flipscope::detail::houdini
