// A small writer of Houdini JSON geometry for the reader's tests: binary JSON (.bgeo: token
// definitions and references, uniform arrays or one token a number, the smallest integer
// tokens) and ASCII JSON (.geo), with point attributes stored paged (pagesize, packing,
// constant pages), as tuples or as arrays; and the scf1 container around any bytes (Blosc LZ4
// chunks, the index and footer as Houdini writes them). Written from the format as the reader
// documents it (preprocess/particles/houdini/), to make cases the real files lack: many
// particles, many pages and chunks, every storage type.
#pragma once

#include <blosc.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace flipscope::testing::bgeo {

enum class Encoding { Binary, Ascii };
enum class Layout { Paged, Tuples, Arrays };

struct Attribute {
  std::string name;
  std::string storage = "fpreal32";  ///< fpreal16/32/64, int8/16/32/64, uint8, uint16
  int arity = 3;
  std::function<double(std::uint64_t point, int component)> value;
  Layout layout = Layout::Paged;
  std::uint64_t pageSize = 1024;
  std::vector<int> packing;     ///< paged: subvector sizes; empty = one
  bool constantPages = true;    ///< paged: pages whose subvector values are all equal are written as constant
  bool uniform = true;          ///< binary: numbers as uniform arrays, else one token each
  bool isString = false;        ///< a string attribute (values: indices into two strings)
};

struct Geometry {
  std::uint64_t points = 0;
  std::vector<Attribute> attributes;
  std::vector<std::string> primitives;  ///< one primitive of each type named, on points 0, 1, ...
  std::string fileVersion = "18.5.408";
  bool tokenStrings = true;  ///< binary: strings through token definitions (Houdini's way)
};

/// IEEE half of `value` (round to nearest, ties away from zero; enough for the tests).
inline std::uint16_t floatToHalf(float value) {
  const auto bits = std::bit_cast<std::uint32_t>(value);
  const std::uint16_t sign = std::uint16_t((bits >> 16) & 0x8000u);
  const int exponent = int((bits >> 23) & 0xffu) - 127 + 15;
  std::uint32_t mantissa = bits & 0x7fffffu;
  if ((bits & 0x7fffffffu) > 0x7f800000u) return std::uint16_t(sign | 0x7e00u);
  if (exponent >= 31) return std::uint16_t(sign | 0x7c00u);
  if (exponent <= 0) {
    if (exponent < -10) return sign;
    mantissa |= 0x800000u;
    const int shift = 14 - exponent;
    return std::uint16_t(sign | ((mantissa + (1u << (shift - 1))) >> shift));
  }
  return std::uint16_t((sign | std::uint32_t(exponent) << 10 | mantissa >> 13) + ((mantissa >> 12) & 1u));
}

/// The JSON token writer, to `out` (flushed to a stream by the caller).
class JsonWriter {
 public:
  JsonWriter(Encoding encoding, bool tokenStrings) : mEncoding(encoding), mTokenStrings(tokenStrings) {
    if (encoding == Encoding::Binary) mOut.append("\x7fNSJb", 5);
  }
  std::string& out() { return mOut; }

  void beginArray() { open('[', 0x5b); }
  void endArray() { close(']', 0x5d); }
  void beginMap() { open('{', 0x7b); }
  void endMap() { close('}', 0x7d); }
  /// A key of a map (the next value is its value).
  void key(std::string_view text) {
    string(text);
    if (mEncoding == Encoding::Ascii) {
      mOut += ':';
      mAfterKey = true;
    }
  }
  void string(std::string_view text) {
    comma();
    if (mEncoding == Encoding::Ascii) {
      mOut += '"';
      mOut += text;  // the tests' strings need no escapes
      mOut += '"';
      return;
    }
    if (!mTokenStrings) {
      byte(0x27);
      length(text.size());
      mOut += text;
      return;
    }
    auto [it, inserted] = mTokens.try_emplace(std::string(text), mTokens.size());
    if (inserted) {
      byte(0x2b);
      length(it->second);
      length(text.size());
      mOut += text;
    }
    byte(0x26);
    length(it->second);
  }
  void integer(std::int64_t value) {
    comma();
    if (mEncoding == Encoding::Ascii) return ascii(value);
    if (value >= -128 && value <= 127) {
      byte(0x11);
      raw(std::int8_t(value));
    } else if (value >= -32768 && value <= 32767) {
      byte(0x12);
      raw(std::int16_t(value));
    } else if (value >= INT32_MIN && value <= INT32_MAX) {
      byte(0x13);
      raw(std::int32_t(value));
    } else {
      byte(0x14);
      raw(value);
    }
  }
  void boolean(bool value) {
    comma();
    if (mEncoding == Encoding::Ascii)
      mOut += value ? "true" : "false";
    else
      byte(value ? 0x31 : 0x30);
  }

  /// A number array of `count` values of `storage`, then number() each, then endNumbers().
  void beginNumbers(const std::string& storage, std::uint64_t count, bool uniform) {
    mStorage = storage;
    mUniform = uniform && mEncoding == Encoding::Binary;
    if (mUniform) {
      comma();
      byte(0x40);
      byte(jidOf(storage));
      length(count);
    } else {
      open('[', 0x5b);
    }
  }
  void number(double value) {
    if (mUniform) return rawValue(value);
    comma();
    if (mEncoding == Encoding::Ascii) {
      if (mStorage == "fpreal32" || mStorage == "fpreal16") return ascii(float(value));
      if (mStorage == "fpreal64") return ascii(value);
      return ascii(std::int64_t(value));
    }
    byte(jidOf(mStorage));
    rawValue(value);
  }
  void endNumbers() {
    if (!mUniform) close(']', 0x5d);
    mUniform = false;
  }
  /// An array of booleans (binary uniform: packed 32 to a word).
  void bools(const std::vector<bool>& flags, bool uniform) {
    if (uniform && mEncoding == Encoding::Binary) {
      comma();
      byte(0x40);
      byte(0x10);
      length(flags.size());
      for (std::size_t w = 0; w < (flags.size() + 31) / 32; ++w) {
        std::uint32_t word = 0;
        for (std::size_t b = 0; b < 32 && w * 32 + b < flags.size(); ++b)
          if (flags[w * 32 + b]) word |= 1u << b;
        raw(word);
      }
      return;
    }
    beginArray();
    for (bool flag : flags) boolean(flag);
    endArray();
  }

 private:
  static std::uint8_t jidOf(const std::string& storage) {
    if (storage == "fpreal32") return 0x19;
    if (storage == "fpreal64") return 0x1a;
    if (storage == "fpreal16") return 0x18;
    if (storage == "int8") return 0x11;
    if (storage == "int16") return 0x12;
    if (storage == "int32") return 0x13;
    if (storage == "int64") return 0x14;
    if (storage == "uint8") return 0x21;
    if (storage == "uint16") return 0x22;
    throw std::invalid_argument("BgeoTestWriter: unknown storage " + storage);
  }
  void rawValue(double value) {
    switch (jidOf(mStorage)) {
      case 0x19: return raw(float(value));
      case 0x1a: return raw(value);
      case 0x18: return raw(floatToHalf(float(value)));
      case 0x11: return raw(std::int8_t(value));
      case 0x12: return raw(std::int16_t(value));
      case 0x13: return raw(std::int32_t(value));
      case 0x14: return raw(std::int64_t(value));
      case 0x21: return raw(std::uint8_t(value));
      case 0x22: return raw(std::uint16_t(value));
    }
  }
  template <class T>
  void raw(T value) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    mOut.append(bytes, sizeof value);
  }
  template <class T>
  void ascii(T value) {
    char text[64];
    mOut.append(text, std::to_chars(text, text + sizeof text, value).ptr);
  }
  void byte(int b) { mOut += char(b); }
  void length(std::uint64_t n) {
    if (n < 0xf1) {
      byte(int(n));
    } else if (n <= 0xffff) {
      byte(0xf2);
      raw(std::uint16_t(n));
    } else if (n <= 0xffffffffu) {
      byte(0xf4);
      raw(std::uint32_t(n));
    } else {
      byte(0xf8);
      raw(n);
    }
  }
  void comma() {
    if (mEncoding != Encoding::Ascii || mLevels.empty()) return;
    if (mAfterKey) {
      mAfterKey = false;
      return;
    }
    if (!mLevels.back().first) mOut += ',';
    mLevels.back().first = false;
  }
  void open(char text, int token) {
    comma();
    if (mEncoding == Encoding::Ascii)
      mOut += text;
    else
      byte(token);
    mLevels.push_back({true, text});
  }
  void close(char text, int token) {
    mLevels.pop_back();
    if (mEncoding == Encoding::Ascii) {
      mOut += text;
      if (!mLevels.empty()) mLevels.back().first = false;
    } else {
      byte(token);
    }
  }

  Encoding mEncoding;
  bool mTokenStrings;
  std::string mOut;
  std::map<std::string, std::uint64_t, std::less<>> mTokens;
  std::vector<std::pair<bool, char>> mLevels;  ///< ASCII: (no element yet, kind) of each open array/map
  bool mAfterKey = false;
  std::string mStorage;
  bool mUniform = false;
};

/// Writes `geometry` to `out`.
inline void writeGeometry(std::ostream& out, const Geometry& geometry, Encoding encoding) {
  JsonWriter w(encoding, geometry.tokenStrings);
  auto flush = [&](bool force) {
    if (force || w.out().size() > (std::size_t(1) << 20)) {
      out.write(w.out().data(), std::streamsize(w.out().size()));
      w.out().clear();
    }
  };
  const std::uint64_t n = geometry.points;
  const auto primitives = std::int64_t(geometry.primitives.size());
  w.beginArray();
  w.string("fileversion");
  w.string(geometry.fileVersion);
  w.string("hasindex");
  w.boolean(false);
  w.string("pointcount");
  w.integer(std::int64_t(n));
  w.string("vertexcount");
  w.integer(primitives);
  w.string("primitivecount");
  w.integer(primitives);
  w.string("info");
  w.beginMap();
  w.key("software");
  w.string("Houdini " + geometry.fileVersion);
  w.key("bounds");
  w.beginArray();
  for (int i = 0; i < 6; ++i) w.integer(i % 2 ? 1 : -1);
  w.endArray();
  w.endMap();
  w.string("topology");
  w.beginArray();
  w.string("pointref");
  w.beginArray();
  w.string("indices");
  w.beginNumbers("int32", std::uint64_t(primitives), true);
  for (std::int64_t i = 0; i < primitives; ++i) w.number(double(i));
  w.endNumbers();
  w.endArray();
  w.endArray();
  w.string("attributes");
  w.beginArray();
  w.string("vertexattributes");
  w.beginArray();
  w.endArray();
  w.string("pointattributes");
  w.beginArray();
  for (const Attribute& a : geometry.attributes) {
    w.beginArray();
    w.beginArray();
    for (const char* key : {"scope", "public", "type"}) w.string(key);
    w.string(a.isString ? "string" : "numeric");
    w.string("name");
    w.string(a.name);
    w.string("options");
    w.beginMap();
    w.endMap();
    w.endArray();
    w.beginArray();
    w.string("size");
    w.integer(a.arity);
    w.string("storage");
    w.string(a.isString ? "int32" : a.storage);
    if (a.isString) {
      w.string("strings");
      w.beginArray();
      w.string("first");
      w.string("second");
      w.endArray();
      w.string("indices");
      w.beginArray();
      w.string("size");
      w.integer(1);
      w.string("storage");
      w.string("int32");
      w.string("arrays");
      w.beginArray();
      w.beginNumbers("int32", n, a.uniform);
      for (std::uint64_t p = 0; p < n; ++p) w.number(double(p % 2));
      w.endNumbers();
      w.endArray();
      w.endArray();
      w.endArray();
      w.endArray();
      continue;
    }
    w.string("defaults");
    w.beginArray();
    w.string("size");
    w.integer(1);
    w.string("storage");
    w.string("fpreal64");
    w.string("values");
    w.beginNumbers("fpreal64", 1, false);
    w.number(0);
    w.endNumbers();
    w.endArray();
    w.string("values");
    w.beginArray();
    w.string("size");
    w.integer(a.arity);
    w.string("storage");
    w.string(a.storage);
    if (a.layout == Layout::Tuples) {
      w.string("tuples");
      w.beginArray();
      for (std::uint64_t p = 0; p < n; ++p) {
        w.beginNumbers(a.storage, std::uint64_t(a.arity), a.uniform);
        for (int c = 0; c < a.arity; ++c) w.number(a.value(p, c));
        w.endNumbers();
        flush(false);
      }
      w.endArray();
    } else if (a.layout == Layout::Arrays) {
      w.string("arrays");
      w.beginArray();
      for (int c = 0; c < a.arity; ++c) {
        w.beginNumbers(a.storage, n, a.uniform);
        for (std::uint64_t p = 0; p < n; ++p) {
          w.number(a.value(p, c));
          if (p % 4096 == 0) flush(false);
        }
        w.endNumbers();
      }
      w.endArray();
    } else {
      const std::vector<int> packing = a.packing.empty() ? std::vector<int>{a.arity} : a.packing;
      const std::uint64_t pages = (n + a.pageSize - 1) / a.pageSize;
      std::vector<std::vector<bool>> constant(packing.size(), std::vector<bool>(pages, false));
      bool anyConstant = false;
      std::uint64_t count = 0;
      for (std::uint64_t page = 0; page < pages; ++page) {
        const std::uint64_t first = page * a.pageSize, last = std::min(n, first + a.pageSize);
        int component = 0;
        for (std::size_t j = 0; j < packing.size(); ++j) {
          bool same = a.constantPages;
          for (std::uint64_t p = first + 1; same && p < last; ++p)
            for (int c = component; same && c < component + packing[j]; ++c) same = a.value(p, c) == a.value(first, c);
          constant[j][page] = same;
          anyConstant = anyConstant || same;
          count += std::uint64_t(packing[j]) * (same ? 1 : last - first);
          component += packing[j];
        }
      }
      w.string("pagesize");
      w.integer(std::int64_t(a.pageSize));
      if (packing.size() > 1) {
        w.string("packing");
        w.beginNumbers("int32", packing.size(), a.uniform);
        for (int size : packing) w.number(size);
        w.endNumbers();
      }
      if (anyConstant) {
        w.string("constantpageflags");
        w.beginArray();
        for (const auto& flags : constant) {
          if (std::find(flags.begin(), flags.end(), true) == flags.end())
            w.bools({}, a.uniform);
          else
            w.bools(flags, a.uniform);
        }
        w.endArray();
      }
      w.string("rawpagedata");
      w.beginNumbers(a.storage, count, a.uniform);
      for (std::uint64_t page = 0; page < pages; ++page) {
        const std::uint64_t first = page * a.pageSize, last = std::min(n, first + a.pageSize);
        int component = 0;
        for (std::size_t j = 0; j < packing.size(); ++j) {
          const std::uint64_t end = constant[j][page] ? first + 1 : last;
          for (std::uint64_t p = first; p < end; ++p)
            for (int c = component; c < component + packing[j]; ++c) w.number(a.value(p, c));
          component += packing[j];
        }
        flush(false);
      }
      w.endNumbers();
    }
    w.endArray();
    w.endArray();
    w.endArray();
  }
  w.endArray();
  w.endArray();
  w.string("primitives");
  w.beginArray();
  for (std::int64_t i = 0; i < primitives; ++i) {
    w.beginArray();
    w.beginArray();
    w.string("type");
    w.string(geometry.primitives[std::size_t(i)]);
    w.endArray();
    w.beginArray();
    w.string("vertex");
    w.integer(i);
    w.endArray();
    w.endArray();
  }
  w.endArray();
  w.endArray();
  if (encoding == Encoding::Ascii) w.out() += '\n';
  flush(true);
}

inline std::string geometryBytes(const Geometry& geometry, Encoding encoding) {
  std::ostringstream out;
  writeGeometry(out, geometry, encoding);
  return std::move(out).str();
}

/// `bytes` in Houdini's scf1 container: Blosc LZ4 chunks of `chunkBytes` decoded bytes (byte
/// shuffle of 4-byte items), the index ({chunkBytes, decoded size} for one chunk, else
/// {chunkBytes, each chunk's decoded size}) and the footer.
inline std::string scfContainer(std::string_view bytes, std::size_t chunkBytes = std::size_t(1) << 20) {
  std::string out("scf1", 4);
  out.append(8, '\0');
  std::vector<std::uint64_t> index{chunkBytes};
  std::vector<char> compressed;
  for (std::size_t at = 0; at < bytes.size(); at += chunkBytes) {
    const std::size_t n = std::min(chunkBytes, bytes.size() - at);
    compressed.resize(n + BLOSC_MAX_OVERHEAD);
    const int size = blosc_compress_ctx(5, BLOSC_SHUFFLE, 4, n, bytes.data() + at, compressed.data(),
                                        compressed.size(), "lz4", 0, 1);
    if (size <= 0) throw std::runtime_error("blosc_compress_ctx failed");
    out.append(compressed.data(), std::size_t(size));
    index.push_back(n);
  }
  auto bigEndian = [&](std::uint64_t value) {
    for (int i = 7; i >= 0; --i) out += char((value >> (8 * i)) & 0xff);
  };
  for (std::uint64_t entry : index) bigEndian(entry);
  bigEndian(8 * index.size());
  out.append("1fcs", 4);
  return out;
}

}  // namespace flipscope::testing::bgeo
