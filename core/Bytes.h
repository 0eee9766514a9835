// Little-endian byte serialization for flipscope's file formats.
// ByteWriter appends; ByteReader reads with bounds checks and throws FileError naming the file,
// the byte offset and the field when the data ends early. Both assume a little-endian host
// (checked at compile time), so fixed-size fields are memcpy'd.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "core/Error.h"

namespace flipscope {

static_assert(std::endian::native == std::endian::little, "flipscope's file formats assume a little-endian host");

class ByteWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(&value, sizeof(T));
  }
  template <class T>
  void putArray(std::span<const T> values) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(values.data(), values.size_bytes());
  }
  /// LEB128 unsigned varint: 7 bits a byte, low bits first.
  void putVarint(std::uint64_t v) {
    while (v >= 0x80) {
      mBytes.push_back(std::byte(v | 0x80));
      v >>= 7;
    }
    mBytes.push_back(std::byte(v));
  }
  void append(const void* data, std::size_t n) {
    auto p = static_cast<const std::byte*>(data);
    mBytes.insert(mBytes.end(), p, p + n);
  }
  std::size_t size() const { return mBytes.size(); }
  std::vector<std::byte>& bytes() { return mBytes; }
  std::span<const std::byte> view() const { return mBytes; }

 private:
  std::vector<std::byte> mBytes;
};

class ByteReader {
 public:
  /// `file` names the source in error messages; `base` is the offset of data[0] in that file.
  ByteReader(std::span<const std::byte> data, std::filesystem::path file, std::uint64_t base = 0)
      : mData(data), mFile(std::move(file)), mBase(base) {}

  template <class T>
  T get(const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T), field), sizeof(T));
    return value;
  }
  template <class T>
  void getArray(std::span<T> out, const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!out.empty()) std::memcpy(out.data(), take(out.size_bytes(), field), out.size_bytes());
  }
  std::uint64_t getVarint(const char* field) {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      auto b = static_cast<std::uint8_t>(*take(1, field));
      v |= std::uint64_t(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    fail(field, "varint longer than 10 bytes");
  }
  /// Reads n varints in a row, calling f(value) for each: getVarint's checks, with the one-byte
  /// varints (most of a brick's cell gaps and counts) read without a call.
  template <class F>
  void forEachVarint(std::size_t n, const char* field, F&& f) {
    const auto* begin = reinterpret_cast<const std::uint8_t*>(mData.data());
    const std::uint8_t* p = begin + mPos;
    const std::uint8_t* const end = begin + mData.size();
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t v;
      if (p != end && *p < 0x80) {
        v = *p++;
      } else {
        mPos = std::size_t(p - begin);
        v = getVarint(field);
        p = begin + mPos;
      }
      f(v);
    }
    mPos = std::size_t(p - begin);
  }
  std::span<const std::byte> getBytes(std::size_t n, const char* field) { return {take(n, field), n}; }

  std::size_t position() const { return mPos; }
  std::size_t remaining() const { return mData.size() - mPos; }
  /// Throws unless every byte was consumed ("trailing bytes").
  void expectEnd(const char* what) const {
    if (remaining() != 0) fail(what, std::to_string(remaining()) + " unexpected trailing bytes");
  }
  [[noreturn]] void fail(const char* field, const std::string& reason) const {
    throw FileError(mFile, "at byte " + std::to_string(mBase + mPos) + " (" + field + "): " + reason);
  }

 private:
  const std::byte* take(std::size_t n, const char* field) {
    if (n > remaining())
      fail(field, "truncated: needs " + std::to_string(n) + " bytes, " + std::to_string(remaining()) + " left");
    auto p = mData.data() + mPos;
    mPos += n;
    return p;
  }

  std::span<const std::byte> mData;
  std::filesystem::path mFile;
  std::uint64_t mBase;
  std::size_t mPos = 0;
};

}  // namespace flipscope
