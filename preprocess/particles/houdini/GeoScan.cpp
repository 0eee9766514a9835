// The first pass over a Houdini JSON geometry: see GeoScan.h.
#include "preprocess/particles/houdini/GeoScan.h"

#include <algorithm>
#include <cstring>
#include <optional>

#include "core/Error.h"

namespace flipscope::detail::houdini {
namespace {

constexpr std::size_t kScanBufferBytes = std::size_t(1) << 18;
constexpr std::size_t kMaxPrimitiveTypes = 64;

std::optional<ValueType> storageType(const std::string& storage) {
  struct Entry {
    const char* name;
    ValueType type;
  };
  static constexpr Entry kTypes[] = {{"fpreal32", ValueType::Float32}, {"fpreal64", ValueType::Float64},
                                     {"fpreal16", ValueType::Float16}, {"int32", ValueType::Int32},
                                     {"int64", ValueType::Int64},      {"int16", ValueType::Int16},
                                     {"int8", ValueType::Int8},        {"uint8", ValueType::UInt8},
                                     {"uint16", ValueType::UInt16},    {"uint32", ValueType::UInt32},
                                     {"uint64", ValueType::UInt64},    {"bool", ValueType::UInt8}};
  for (const auto& entry : kTypes)
    if (storage == entry.name) return entry.type;
  return std::nullopt;
}

/// What the scan counted of an attribute's values, checked once the point count is known.
struct ValueCounts {
  bool present = false;
  std::uint64_t offset = 0;      ///< where "values" starts, for messages
  std::uint64_t values = 0;      ///< Paged: numbers in rawpagedata; Tuples: tuples
  std::uint64_t tupleSize = 0;   ///< Tuples: numbers in each tuple
  std::vector<std::uint64_t> arrayLengths;  ///< Arrays: numbers in each component's array
};

class Scanner {
 public:
  Scanner(InputFile& file, JsonEncoding encoding, std::uint64_t start)
      : mIn(file, encoding, start, kScanBufferBytes) {
    mLayout.encoding = encoding;
  }

  GeoLayout run() {
    const std::uint64_t start = mIn.offset();
    mIn.readEntries("the geometry", [&](const std::string& key) { topLevel(key); });
    if (!mIn.atEnd()) mIn.fail(mIn.offset(), "unexpected bytes after the end of the geometry");
    if (!mSeenPointCount) mIn.fail(start, "the geometry has no \"pointcount\"");
    for (std::size_t i = 0; i < mAttributes.size(); ++i) check(mAttributes[i], mCounts[i]);
    return std::move(mLayout);
  }

 private:
  std::string quoted(const std::string& name) const { return "point attribute '" + name + "'"; }

  std::uint64_t readCount(const std::string& what) {
    const std::uint64_t at = mIn.offset();
    const std::int64_t value = mIn.readInteger(what);
    if (value < 0 || std::uint64_t(value) > kMaxPoints)
      mIn.fail(at, what + " " + std::to_string(value) + " is out of range (0 to " + std::to_string(kMaxPoints) + ")");
    return std::uint64_t(value);
  }

  void topLevel(const std::string& key) {
    if (key == "fileversion") {
      mLayout.fileVersion = mIn.readString("fileversion");
    } else if (key == "pointcount") {
      mLayout.pointCount = readCount("pointcount");
      mSeenPointCount = true;
    } else if (key == "vertexcount") {
      mLayout.vertexCount = readCount("vertexcount");
    } else if (key == "primitivecount") {
      mLayout.primitiveCount = readCount("primitivecount");
    } else if (key == "attributes") {
      mIn.readEntries("attributes", [&](const std::string& kind) {
        if (kind != "pointattributes") return mIn.skipValue();
        mIn.beginArray("pointattributes");
        while (!mIn.endOfArray()) pointAttribute();
      });
    } else if (key == "primitives") {
      primitives();
    } else {
      mIn.skipValue();
    }
  }

  void pointAttribute() {
    const std::uint64_t at = mIn.offset();
    mIn.beginArray("a point attribute");
    PointAttribute attribute;
    attribute.arity = 0;  // from "size", below
    std::string type;
    mIn.readEntries("point attribute metadata", [&](const std::string& key) {
      if (key == "name")
        attribute.name = mIn.readString("point attribute name");
      else if (key == "type")
        type = mIn.readString("point attribute type");
      else
        mIn.skipValue();
    });
    const std::string what = quoted(attribute.name);
    std::int64_t size = 0;
    ValueCounts counts;
    if (mIn.peek() != TokenKind::ArrayEnd) {
      mIn.readEntries(what, [&](const std::string& key) {
        if (key == "size")
          size = mIn.readInteger(what + " size");
        else if (key == "storage")
          attribute.storage = mIn.readString(what + " storage");
        else if (key == "values" && type == "numeric")
          values(attribute, size, counts);
        else
          mIn.skipValue();
      });
    }
    while (!mIn.endOfArray()) mIn.skipValue();
    if (type != "numeric") return;  // strings, arrays, ...: not particle values
    if (attribute.name.empty()) mIn.fail(at, "a numeric point attribute without a name");
    for (const auto& other : mAttributes)
      if (other.name == attribute.name) mIn.fail(at, "two point attributes named '" + attribute.name + "'");
    if (attribute.arity == 0) attribute.arity = int(std::clamp<std::int64_t>(size, -1, kMaxArity + 1));
    if (attribute.arity < 1 || attribute.arity > kMaxArity)
      mIn.fail(at, what + ": size " + std::to_string(attribute.arity) + " is out of range (1 to " +
                       std::to_string(kMaxArity) + ")");
    if (!counts.present) counts.offset = at;
    mAttributes.push_back(std::move(attribute));
    mCounts.push_back(std::move(counts));
  }

  /// Small non-negative integers ("packing").
  std::vector<int> readSmallIntegers(const std::string& what) {
    std::vector<int> result;
    NumberArray array = mIn.beginNumbers(what);
    for (;;) {
      if (array.uniform ? array.remaining == 0 : mIn.peek() == TokenKind::ArrayEnd) break;
      float value = 0;
      mIn.readNumbers(array, &value, 1, what);
      if (!(value >= 1 && value <= float(kMaxArity)) || value != float(int(value)) || result.size() == kMaxArity)
        mIn.fail(array.offset, what + ": expected sizes from 1 to " + std::to_string(kMaxArity));
      result.push_back(int(value));
    }
    mIn.endNumbers(array, what);
    return result;
  }

  void values(PointAttribute& attribute, std::int64_t size, ValueCounts& counts) {
    const std::string what = quoted(attribute.name);
    counts.offset = mIn.offset();
    if (counts.present) mIn.fail(counts.offset, what + ": a second \"values\"");
    counts.present = true;
    attribute.arity = int(std::clamp<std::int64_t>(size, -1, kMaxArity + 1));
    bool haveData = false;
    auto startData = [&](ValueLayout layout, const char* key) {
      if (haveData) mIn.fail(mIn.offset(), what + ": \"" + key + "\" besides other values");
      haveData = true;
      attribute.layout = layout;
      mIn.peek();
      attribute.dataOffsets.assign(1, mIn.offset());
    };
    mIn.readEntries(what + " values", [&](const std::string& key) {
      if (key == "size") {
        attribute.arity = int(std::clamp<std::int64_t>(mIn.readInteger(what + " size"), -1, kMaxArity + 1));
      } else if (key == "storage") {
        attribute.storage = mIn.readString(what + " storage");
      } else if (key == "pagesize") {
        const std::uint64_t at = mIn.offset();
        const std::int64_t pageSize = mIn.readInteger(what + " pagesize");
        if (pageSize < 1 || std::uint64_t(pageSize) > kMaxPageSize)
          mIn.fail(at, what + ": pagesize " + std::to_string(pageSize) + " is out of range (1 to " +
                           std::to_string(kMaxPageSize) + ")");
        attribute.pageSize = std::uint64_t(pageSize);
      } else if (key == "packing") {
        attribute.packing = readSmallIntegers(what + " packing");
      } else if (key == "constantpageflags") {
        mIn.beginArray(what + " constantpageflags");
        while (!mIn.endOfArray()) {
          if (attribute.constantPages.size() == kMaxArity)
            mIn.fail(mIn.offset(), what + ": more constantpageflags than components");
          attribute.constantPages.push_back(mIn.readBools(what + " constantpageflags"));
        }
      } else if (key == "rawpagedata") {
        startData(ValueLayout::Paged, "rawpagedata");
        NumberArray array = mIn.beginNumbers(what + " rawpagedata");
        counts.values = mIn.skipNumbers(array, what + " rawpagedata");
      } else if (key == "tuples") {
        startData(ValueLayout::Tuples, "tuples");
        mIn.beginArray(what + " tuples");
        while (!mIn.endOfArray()) {
          const std::uint64_t at = mIn.offset();
          NumberArray tuple = mIn.beginNumbers(what + " tuple");
          const std::uint64_t n = mIn.skipNumbers(tuple, what + " tuple");
          if (counts.values > 0 && n != counts.tupleSize)
            mIn.fail(at, what + ": tuple " + std::to_string(counts.values) + " holds " + std::to_string(n) +
                             " numbers, the ones before it " + std::to_string(counts.tupleSize));
          counts.tupleSize = n;
          ++counts.values;
        }
      } else if (key == "arrays") {
        startData(ValueLayout::Arrays, "arrays");
        attribute.dataOffsets.clear();
        mIn.beginArray(what + " arrays");
        while (!mIn.endOfArray()) {
          if (attribute.dataOffsets.size() == kMaxArity) mIn.fail(mIn.offset(), what + ": more arrays than components");
          mIn.peek();
          attribute.dataOffsets.push_back(mIn.offset());
          NumberArray array = mIn.beginNumbers(what + " array");
          counts.arrayLengths.push_back(mIn.skipNumbers(array, what + " array"));
        }
      } else {
        mIn.skipValue();
      }
    });
    if (!haveData) counts.present = false;
  }

  void primitives() {
    mIn.beginArray("primitives");
    while (!mIn.endOfArray()) {
      if (mIn.peek() != TokenKind::ArrayBegin) {
        mIn.skipValue();
        continue;
      }
      mIn.beginArray("a primitive");
      std::string type, runType;
      if (mIn.peek() == TokenKind::ArrayBegin || mIn.peek() == TokenKind::MapBegin) {
        mIn.readEntries("a primitive's header", [&](const std::string& key) {
          if (key == "type")
            type = mIn.readString("primitive type");
          else if (key == "runtype")
            runType = mIn.readString("primitive runtype");
          else
            mIn.skipValue();
        });
      }
      while (!mIn.endOfArray()) mIn.skipValue();
      if (type == "run" && !runType.empty()) type = runType;
      if (type.empty()) type = "unknown";
      auto found = std::find_if(mLayout.primitiveTypes.begin(), mLayout.primitiveTypes.end(),
                                [&](const auto& entry) { return entry.first == type; });
      if (found != mLayout.primitiveTypes.end())
        ++found->second;
      else if (mLayout.primitiveTypes.size() < kMaxPrimitiveTypes)
        mLayout.primitiveTypes.emplace_back(type, 1);
    }
  }

  /// Checks the counts of `attribute` against the point count; keeps it if it can be read.
  void check(PointAttribute& attribute, const ValueCounts& counts) {
    const std::string what = quoted(attribute.name);
    const std::uint64_t points = mLayout.pointCount;
    auto fail = [&](const std::string& message) { mIn.fail(counts.offset, what + ": " + message); };
    const auto type = storageType(attribute.storage);
    if (!type) {
      if (attribute.name == "P") fail("unknown storage '" + attribute.storage + "'");
      return;  // a numeric attribute of a storage we do not know: not listed
    }
    attribute.type = *type;
    if (!counts.present) {
      if (points > 0) fail("no values (expected " + std::to_string(points) + " points of them)");
      mLayout.pointAttributes.push_back(std::move(attribute));
      return;
    }
    const auto arity = std::uint64_t(attribute.arity);
    switch (attribute.layout) {
      case ValueLayout::Paged: {
        if (attribute.pageSize == 0) fail("rawpagedata without a pagesize");
        if (attribute.pageSize * arity > kMaxPageValues)
          fail("pages of " + std::to_string(attribute.pageSize) + " points of " + std::to_string(arity) +
               " components are too large");
        if (attribute.packing.empty()) attribute.packing.assign(1, attribute.arity);
        std::uint64_t sum = 0;
        for (int size : attribute.packing) sum += std::uint64_t(size);
        if (sum != arity)
          fail("packing adds up to " + std::to_string(sum) + " components, its size is " + std::to_string(arity));
        if (attribute.constantPages.empty()) attribute.constantPages.resize(attribute.packing.size());
        if (attribute.constantPages.size() != attribute.packing.size())
          fail(std::to_string(attribute.constantPages.size()) + " lists of constantpageflags for " +
               std::to_string(attribute.packing.size()) + " packed subvectors");
        const std::uint64_t pages = (points + attribute.pageSize - 1) / attribute.pageSize;
        for (const auto& flags : attribute.constantPages)
          if (!flags.empty() && flags.size() != pages)
            fail(std::to_string(flags.size()) + " constantpageflags for " + std::to_string(pages) + " pages");
        const std::uint64_t expected = pagedValueCount(attribute, points);
        if (counts.values != expected)
          fail("rawpagedata holds " + std::to_string(counts.values) + " numbers, expected " + std::to_string(expected) +
               " (" + std::to_string(points) + " points, pagesize " + std::to_string(attribute.pageSize) + ")");
        break;
      }
      case ValueLayout::Tuples:
        if (counts.values != points)
          fail(std::to_string(counts.values) + " tuples for " + std::to_string(points) + " points");
        if (points > 0 && counts.tupleSize != arity)
          fail("tuples of " + std::to_string(counts.tupleSize) + " numbers, its size is " + std::to_string(arity));
        break;
      case ValueLayout::Arrays:
        if (counts.arrayLengths.size() != arity)
          fail(std::to_string(counts.arrayLengths.size()) + " arrays for " + std::to_string(arity) + " components");
        for (std::size_t c = 0; c < counts.arrayLengths.size(); ++c)
          if (counts.arrayLengths[c] != points)
            fail("array " + std::to_string(c) + " holds " + std::to_string(counts.arrayLengths[c]) + " numbers for " +
                 std::to_string(points) + " points");
        break;
    }
    mLayout.pointAttributes.push_back(std::move(attribute));
  }

  JsonReader mIn;
  GeoLayout mLayout;
  bool mSeenPointCount = false;
  std::vector<PointAttribute> mAttributes;
  std::vector<ValueCounts> mCounts;
};

}  // namespace

std::uint64_t pagedValueCount(const PointAttribute& attribute, std::uint64_t points) {
  const std::uint64_t pageSize = attribute.pageSize;
  const std::uint64_t pages = (points + pageSize - 1) / pageSize;
  const std::uint64_t lastPage = points - (pages ? (pages - 1) * pageSize : 0);
  std::uint64_t total = 0;
  for (std::size_t j = 0; j < attribute.packing.size(); ++j) {
    const auto size = std::uint64_t(attribute.packing[j]);
    const std::vector<bool>& flags = attribute.constantPages[j];
    std::uint64_t constantPages = 0, constantPoints = 0;
    for (std::uint64_t page = 0; page < flags.size(); ++page)
      if (flags[page]) {
        ++constantPages;
        constantPoints += page + 1 == pages ? lastPage : pageSize;
      }
    total += size * (points - constantPoints + constantPages);
  }
  return total;
}

GeoLayout scanGeometry(InputFile& file, JsonEncoding encoding) {
  std::uint64_t start = 0;
  if (encoding == JsonEncoding::Binary) {
    unsigned char magic[5] = {};
    const std::size_t got = file.readAt(0, magic, sizeof magic);
    if (got == sizeof magic && std::memcmp(magic, kSwappedMagic, sizeof magic) == 0)
      throw FileError(file.path(), "byte-swapped (big-endian) Houdini binary JSON is not supported");
    if (got != sizeof magic || std::memcmp(magic, kBinaryMagic, sizeof magic) != 0)
      throw FileError(file.path(), "bad magic: not a Houdini binary JSON geometry (expected 7f 4e 53 4a 62, \"\\x7fNSJb\")");
    start = sizeof magic;
  }
  return Scanner(file, encoding, start).run();
}

}  // namespace flipscope::detail::houdini
