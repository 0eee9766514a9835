// VTK legacy particle files (.vtk: "# vtk DataFile Version x.y", then a title line, ASCII or
// BINARY, and a DATASET; described in the VTK User's Guide, "Simple Legacy Formats", and at
// docs.vtk.org, "VTK File Formats"). Reads the POINTS of a POLYDATA or UNSTRUCTURED_GRID
// dataset and its POINT_DATA arrays (SCALARS, COLOR_SCALARS, VECTORS, NORMALS,
// TEXTURE_COORDINATES, TENSORS, TENSORS6, GLOBAL_IDS, PEDIGREE_IDS and FIELD arrays) of any
// numeric type, BINARY ones big-endian. Skips, by their declared sizes, the cells (VERTICES,
// LINES, POLYGONS, TRIANGLE_STRIPS, CELLS, CELL_TYPES; also the OFFSETS/CONNECTIVITY layout of
// version 5), CELL_DATA, dataset FIELD data, LOOKUP_TABLEs and METADATA. Other datasets
// (STRUCTURED_POINTS, STRUCTURED_GRID, RECTILINEAR_GRID) are grids: refused. `long` is taken as
// 8 bytes (VTK writes sizeof(long) bytes: LP64 machines), `vtkIdType` as 4 (VTK writes it as int).
//
// Streaming: VTK stores each array whole, one after the other. Opening the file walks its
// sections once: in BINARY files every size follows from the header lines (a few seeks); in
// ASCII files the values of every section are counted (not parsed). read() then reads each
// array it needs at its own place: BINARY by offset, memory bounded by the chunk; ASCII through
// one buffered cursor per array (256 KiB each), numbers parsed by std::from_chars.
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>

#include "core/Error.h"
#include "preprocess/particles/FileCursor.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/ValueDecode.h"

namespace flipscope::detail {
namespace {

constexpr std::size_t kMaxWordBytes = 1024;
constexpr std::size_t kMaxLineBytes = 1 << 16;
constexpr std::size_t kAsciiCursorBytes = 256 << 10;
constexpr std::uint64_t kDecodeBytes = 256 << 10;  ///< BINARY values are read and decoded in pieces of this
constexpr std::uint64_t kMaxArity = 1 << 20;
constexpr std::string_view kMagic = "# vtk DataFile Version";

/// A legacy data type: its ValueType, and its bytes in BINARY files (bit arrays: packed).
struct LegacyType {
  ValueType type = ValueType::Float32;
  std::size_t bytes = 4;
  bool bit = false;
};

std::optional<LegacyType> legacyType(const std::string& name) {
  struct Entry {
    std::string_view name;
    LegacyType type;
  };
  static constexpr std::array<Entry, 18> kTypes{{
      {"bit", {ValueType::UInt8, 0, true}},
      {"unsigned_char", {ValueType::UInt8, 1}},
      {"char", {ValueType::Int8, 1}},
      {"signed_char", {ValueType::Int8, 1}},
      {"unsigned_short", {ValueType::UInt16, 2}},
      {"short", {ValueType::Int16, 2}},
      {"unsigned_int", {ValueType::UInt32, 4}},
      {"int", {ValueType::Int32, 4}},
      {"vtkidtype", {ValueType::Int32, 4}},
      {"unsigned_long", {ValueType::UInt64, 8}},
      {"long", {ValueType::Int64, 8}},
      {"unsigned_long_long", {ValueType::UInt64, 8}},
      {"long_long", {ValueType::Int64, 8}},
      {"vtktypeuint64", {ValueType::UInt64, 8}},
      {"vtktypeint64", {ValueType::Int64, 8}},
      {"float", {ValueType::Float32, 4}},
      {"double", {ValueType::Float64, 8}},
      {"vtktypefloat64", {ValueType::Float64, 8}},
  }};
  for (const auto& entry : kTypes)
    if (entry.name == name) return entry.type;
  return std::nullopt;
}

/// VTK writes names with spaces and other special bytes as %XX.
std::string decodeName(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    auto hex = [](char c) -> int {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    if (text[i] == '%' && i + 2 < text.size() && hex(text[i + 1]) >= 0 && hex(text[i + 2]) >= 0) {
      out += char(hex(text[i + 1]) * 16 + hex(text[i + 2]));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

struct LegacyArray {
  AttributeDesc desc;
  LegacyType type;
  std::uint64_t offset = 0;  ///< BINARY: the first byte of the values; ASCII: where their text starts
  std::uint64_t keywordOffset = 0;
};

struct LegacyLayout {
  std::string version;
  int major = 0;
  std::string title;
  bool binary = false;
  std::string dataset;
  bool hasPoints = false;
  std::uint64_t points = 0;
  LegacyArray positions;
  std::vector<LegacyArray> pointData;
};

/// Walks the sections of a legacy file (see the file comment).
class LayoutParser {
 public:
  explicit LayoutParser(InputFile& file) : mCursor(file, 0, file.size()) {}

  LegacyLayout parse() {
    std::string_view first = mCursor.line(kMaxLineBytes, "the first line");
    if (first.substr(0, kMagic.size()) != kMagic)
      fail("not a legacy VTK file: the first line is '" + std::string(first.substr(0, 40)) + "', expected '" +
           std::string(kMagic) + " x.x'");
    std::string_view version = first.substr(kMagic.size());
    while (!version.empty() && isSpaceByte(version.front())) version.remove_prefix(1);
    while (!version.empty() && isSpaceByte(version.back())) version.remove_suffix(1);
    mLayout.version = std::string(version.substr(0, 20));
    std::from_chars(version.data(), version.data() + version.size(), mLayout.major);
    mLayout.title = std::string(mCursor.line(kMaxLineBytes, "the title line (line 2)"));
    std::string format = asciiLower(mCursor.word(kMaxWordBytes, "the format line (line 3)"));
    if (format != "ascii" && format != "binary")
      fail("line 3: expected ASCII or BINARY, found '" + format.substr(0, 40) + "'");
    mLayout.binary = format == "binary";
    mCursor.endLine("ASCII or BINARY on line 3");
    for (;;) {
      std::string_view word = mCursor.word(kMaxWordBytes, "a keyword");
      if (word.empty()) break;
      mKeywordOffset = mCursor.offset() - word.size();
      mKeywordText = std::string(word.substr(0, 40));
      section(asciiLower(word));
    }
    if (mLayout.dataset.empty()) fail("no DATASET in the file: it holds no points");
    if (!mLayout.hasPoints) fail("the " + mLayout.dataset + " dataset has no POINTS: no particles");
    return std::move(mLayout);
  }

 private:
  enum class Section { Geometry, Point, Cell };

  [[noreturn]] void fail(const std::string& message) const { mCursor.fail("VTK legacy: " + message); }
  std::string at() const { return mKeywordText + " at byte " + std::to_string(mKeywordOffset); }

  std::string word(const char* what) {
    std::string_view w = mCursor.word(kMaxWordBytes, what);
    if (w.empty()) fail("truncated: the file ends before " + std::string(what) + " of " + at());
    return std::string(w);
  }
  std::uint64_t count(const char* what) {
    std::string text = word(what);
    std::uint64_t value = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size())
      fail("malformed " + std::string(what) + " '" + text.substr(0, 40) + "' of " + at());
    return value;
  }
  std::uint64_t arity(const char* what) {
    std::uint64_t value = count(what);
    if (value == 0 || value > kMaxArity)
      fail(std::string(what) + " " + std::to_string(value) + " of " + at() + " is out of range (1 to " +
           std::to_string(kMaxArity) + ")");
    return value;
  }
  LegacyType type(const char* what) {
    std::string name = asciiLower(word(what));
    if (auto type = legacyType(name)) return *type;
    if (name == "string" || name == "utf8_string" || name == "variant")
      fail(at() + " holds " + name + " values, which flipscope does not read");
    fail("unknown data type '" + name.substr(0, 40) + "' of " + at());
  }
  /// The end of a header line: BINARY values start after its line break.
  void headerEnd() {
    if (mLayout.binary) mCursor.endLine(at());
  }

  /// Skips `values` values of `type` (BINARY: by their size; ASCII: counted).
  void skipValues(std::uint64_t values, const LegacyType& type, const std::string& what) {
    if (!mLayout.binary) {
      mCursor.skipWords(values, false, what);
      return;
    }
    const std::uint64_t left = mCursor.remaining();
    constexpr std::uint64_t kUnknown = std::numeric_limits<std::uint64_t>::max();
    const std::uint64_t bytes = type.bit                         ? values / 8 + (values % 8 != 0)
                                : values > kUnknown / type.bytes ? kUnknown
                                                                 : values * type.bytes;
    if (bytes > left)
      fail("truncated: " + what + " declares " + std::to_string(values) + " values" +
           (bytes == kUnknown ? std::string() : " (" + std::to_string(bytes) + " bytes)") + " at byte " +
           std::to_string(mCursor.offset()) + ", but the file has " + std::to_string(left) + " bytes left");
    mCursor.seek(mCursor.offset() + bytes);
  }

  std::uint64_t product(std::uint64_t a, std::uint64_t b) {
    if (b != 0 && a > std::numeric_limits<std::uint64_t>::max() / b)
      fail(at() + " declares more values than fit in 64 bits (" + std::to_string(a) + " x " + std::to_string(b) + ")");
    return a * b;
  }

  /// The values of an array of the current section: recorded for POINT_DATA, skipped otherwise.
  void array(std::string name, const LegacyType& type, std::uint64_t arity, std::uint64_t tuples) {
    const std::uint64_t values = product(tuples, arity);
    const std::string what = at() + " ('" + name.substr(0, 40) + "')";
    if (mSection == Section::Point)
      mLayout.pointData.push_back({{std::move(name), type.type, int(arity)}, type, mCursor.offset(), mKeywordOffset});
    skipValues(values, type, what);
    metadata();
  }

  /// An optional METADATA block after an array: lines up to an empty line.
  void metadata() {
    if (!peekWordIs("metadata")) return;
    mCursor.word(kMaxWordBytes, "METADATA");
    metadataBlock();
  }
  void metadataBlock() {
    const std::uint64_t start = mCursor.offset();
    mCursor.line(kMaxLineBytes, "the METADATA line");
    for (;;) {
      if (mCursor.atEnd()) fail("truncated: the METADATA block at byte " + std::to_string(start) + " has no end");
      std::string_view line = mCursor.line(kMaxLineBytes, "a METADATA line");
      if (std::all_of(line.begin(), line.end(), [](char c) { return isSpaceByte(c); })) return;
    }
  }

  /// Whether the next word (after whitespace) is `keyword`, case-insensitively; consumes nothing
  /// but the whitespace.
  bool peekWordIs(std::string_view keyword) {
    while (mCursor.peek() >= 0 && isSpaceByte(char(mCursor.peek()))) mCursor.advance(1);
    return bytesAre(keyword);
  }
  /// Whether the bytes at the cursor are `keyword` (case-insensitively) followed by whitespace.
  bool bytesAre(std::string_view keyword) {
    auto w = mCursor.window(keyword.size() + 1);
    if (w.size() < keyword.size() + 1 || !isSpaceByte(w[keyword.size()])) return false;
    for (std::size_t i = 0; i < keyword.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(w[i])) != keyword[i]) return false;
    return true;
  }

  void needAttributes() {
    if (mSection == Section::Geometry) fail(at() + " comes before POINT_DATA or CELL_DATA");
  }

  void section(const std::string& keyword) {
    if (keyword == "dataset") {
      if (!mLayout.dataset.empty()) fail("second DATASET, " + at());
      std::string type = word("the dataset type");
      for (char& c : type) c = char(std::toupper(static_cast<unsigned char>(c)));
      if (type != "POLYDATA" && type != "UNSTRUCTURED_GRID") {
        const bool grid = type == "STRUCTURED_POINTS" || type == "STRUCTURED_GRID" || type == "RECTILINEAR_GRID" ||
                          type == "IMAGE_DATA";
        fail("the dataset type is " + type.substr(0, 40) + (grid ? ", a grid" : "") +
             ", not particles (flipscope reads the POINTS of POLYDATA and UNSTRUCTURED_GRID datasets)");
      }
      mLayout.dataset = type;
      return;
    }
    if (mLayout.dataset.empty()) {
      if (keyword == "field") fail("the file holds a FIELD data object (no DATASET): no points, not particles");
      fail("expected DATASET at byte " + std::to_string(mKeywordOffset) + ", found '" + mKeywordText + "'");
    }
    if (keyword == "points") {
      if (mLayout.hasPoints) fail("second POINTS, " + at());
      mLayout.points = count("point count");
      const LegacyType t = type("point type");
      headerEnd();
      mLayout.hasPoints = true;
      mLayout.positions = {{"P", t.type, 3}, t, mCursor.offset(), mKeywordOffset};
      skipValues(product(mLayout.points, 3), t, at());
      metadata();
    } else if (keyword == "vertices" || keyword == "lines" || keyword == "polygons" || keyword == "triangle_strips" ||
               keyword == "cells") {
      const std::uint64_t cells = count("cell count");
      const std::uint64_t size = count("size");
      headerEnd();
      if (mLayout.major >= 5) {
        for (auto [part, values] : {std::pair{"offsets", cells}, {"connectivity", size}}) {
          if (!peekWordIs(part))
            fail(std::string("expected ") + (values == cells ? "OFFSETS" : "CONNECTIVITY") + " after " + at() +
                 " (the cell layout of version " + mLayout.version + ")");
          std::string label = word("OFFSETS or CONNECTIVITY");
          const LegacyType t = type("cell index type");
          headerEnd();
          skipValues(values, t, label + " of " + at());
        }
      } else {
        skipValues(size, LegacyType{ValueType::Int32, 4}, at());
      }
    } else if (keyword == "cell_types") {
      const std::uint64_t cells = count("cell count");
      headerEnd();
      skipValues(cells, LegacyType{ValueType::Int32, 4}, at());
    } else if (keyword == "point_data") {
      if (!mLayout.hasPoints) fail(at() + " comes before POINTS");
      if (mSeenPointData) fail("second POINT_DATA, " + at());
      const std::uint64_t n = count("point count");
      if (n != mLayout.points)
        fail(at() + " declares " + std::to_string(n) + " points, POINTS " + std::to_string(mLayout.points));
      mSeenPointData = true;
      mSection = Section::Point;
      mTuples = n;
    } else if (keyword == "cell_data") {
      mTuples = count("cell count");
      mSection = Section::Cell;
    } else if (keyword == "field") {
      word("the field name");
      const std::uint64_t arrays = count("array count");
      const std::uint64_t fieldOffset = mKeywordOffset;
      for (std::uint64_t i = 0; i < arrays; ++i) {
        std::string name = word("a field array name");
        mKeywordOffset = mCursor.offset() - name.size();
        mKeywordText = "FIELD array '" + decodeName(name).substr(0, 40) + "'";
        if (asciiLower(name) == "null_array") continue;
        const std::uint64_t components = arity("component count");
        const std::uint64_t tuples = count("tuple count");
        const LegacyType t = type("array type");
        headerEnd();
        if (mSection == Section::Point && tuples != mTuples)
          fail(at() + " has " + std::to_string(tuples) + " tuples, POINT_DATA " + std::to_string(mTuples) +
               " (FIELD at byte " + std::to_string(fieldOffset) + ")");
        array(decodeName(name), t, components, tuples);
      }
    } else if (keyword == "scalars") {
      needAttributes();
      std::string name = decodeName(word("the array name"));
      const LegacyType t = type("array type");
      std::uint64_t components = 1;
      std::string_view more = mCursor.wordOnLine(kMaxWordBytes, at());
      if (!more.empty()) {
        auto [end, ec] = std::from_chars(more.data(), more.data() + more.size(), components);
        if (ec != std::errc() || end != more.data() + more.size() || components == 0 || components > kMaxArity)
          fail("malformed component count '" + std::string(more.substr(0, 40)) + "' of " + at());
      }
      headerEnd();
      if (mLayout.binary ? bytesAre("lookup_table") : peekWordIs("lookup_table")) {
        mCursor.word(kMaxWordBytes, "LOOKUP_TABLE");
        word("the lookup table name");
        headerEnd();
      }
      array(std::move(name), t, components, mTuples);
    } else if (keyword == "color_scalars") {
      needAttributes();
      std::string name = decodeName(word("the array name"));
      const std::uint64_t components = arity("component count");
      headerEnd();
      array(std::move(name), mLayout.binary ? LegacyType{ValueType::UInt8, 1} : LegacyType{ValueType::Float32, 4},
            components, mTuples);
    } else if (keyword == "vectors" || keyword == "normals" || keyword == "tensors" || keyword == "tensors6" ||
               keyword == "global_ids" || keyword == "pedigree_ids") {
      needAttributes();
      std::string name = decodeName(word("the array name"));
      const LegacyType t = type("array type");
      headerEnd();
      const std::uint64_t components = keyword == "tensors"                     ? 9
                                       : keyword == "tensors6"                  ? 6
                                       : keyword[0] == 'g' || keyword[0] == 'p' ? 1
                                                                                : 3;
      array(std::move(name), t, components, mTuples);
    } else if (keyword == "texture_coordinates") {
      needAttributes();
      std::string name = decodeName(word("the array name"));
      const std::uint64_t components = arity("dimension");
      const LegacyType t = type("array type");
      headerEnd();
      array(std::move(name), t, components, mTuples);
    } else if (keyword == "lookup_table") {
      needAttributes();
      word("the table name");
      const std::uint64_t size = count("table size");
      headerEnd();
      skipValues(product(size, 4), mLayout.binary ? LegacyType{ValueType::UInt8, 1} : LegacyType{ValueType::Float32, 4},
                 at());
    } else if (keyword == "metadata") {
      metadataBlock();
    } else {
      fail("unknown keyword '" + mKeywordText + "' at byte " + std::to_string(mKeywordOffset));
    }
  }

  FileCursor mCursor;
  LegacyLayout mLayout;
  Section mSection = Section::Geometry;
  std::uint64_t mTuples = 0;
  bool mSeenPointData = false;
  std::uint64_t mKeywordOffset = 0;
  std::string mKeywordText;
};

class VtkLegacyReader final : public ParticleSource {
 public:
  VtkLegacyReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    mLayout = LayoutParser(mFile).parse();
    for (const auto& array : mLayout.pointData) mAttributes.push_back(array.desc);
    mSelected = selectAttributes(mAttributes, options, mFile.path());
    if (options.velocity) mVelocity = velocityAttributeByName(mAttributes);
    mStreams.push_back(stream(mLayout.positions));
    if (mVelocity) mVelocityStream = addStream(*mVelocity);
    for (std::size_t index : mSelected) mColumnStreams.push_back(addStream(index));
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    std::string title = mLayout.title.substr(0, 80);
    return "VTK legacy " + mLayout.version + " (" + (mLayout.binary ? "binary" : "ASCII") + ", " + mLayout.dataset +
           ")" + (title.empty() ? "" : ": '" + title + "'");
  }
  std::vector<AttributeDesc> attributes() const override { return mAttributes; }
  bool hasVelocity() const override { return mVelocity.has_value(); }
  std::optional<std::uint64_t> countHint() const override { return mLayout.points; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    const std::uint64_t n = std::min<std::uint64_t>(maxParticles, mLayout.points - mNext);
    if (n == 0) {
      chunk.clear();
      chunk.attributes.clear();
      return false;
    }
    const detail::FloatStreams streams{mStreams.size(), mVelocity.has_value(), mVelocityStream, mColumnStreams};
    detail::fillFromFloatStreams(
        chunk, std::size_t(n), streams, mAttributes, mSelected,
        [&](std::size_t stream) { return int(mStreams[stream].array->desc.arity); },
        [&](std::size_t stream, std::size_t count, float* out) { readStream(mStreams[stream], count, out); });
    mNext += n;
    return true;
  }

  void rewind() override {
    mNext = 0;
    for (auto& s : mStreams)
      if (s.cursor) s.cursor->seek(s.array->offset);
  }

 private:
  struct Stream {
    const LegacyArray* array = nullptr;
    std::unique_ptr<FileCursor> cursor;  ///< ASCII only
    std::vector<std::byte> bytes;        ///< BINARY scratch
  };

  Stream stream(const LegacyArray& array) {
    Stream s;
    s.array = &array;
    if (!mLayout.binary) s.cursor = std::make_unique<FileCursor>(mFile, array.offset, mFile.size(), kAsciiCursorBytes);
    return s;
  }
  /// The stream of point-data array `index`, shared by every use of it.
  std::size_t addStream(std::size_t index) {
    const LegacyArray* array = &mLayout.pointData[index];
    for (std::size_t i = 1; i < mStreams.size(); ++i)
      if (mStreams[i].array == array) return i;
    mStreams.push_back(stream(*array));
    return mStreams.size() - 1;
  }

  /// The next `n` tuples of `s` into `out`.
  void readStream(Stream& s, std::uint64_t n, float* out) {
    const LegacyArray& array = *s.array;
    const std::uint64_t arity = std::uint64_t(array.desc.arity);
    const std::uint64_t count = n * arity, first = mNext * arity;
    const std::string what = &array == &mLayout.positions ? "POINTS" : "array '" + array.desc.name + "'";
    if (s.cursor) {
      s.cursor->parseNumbers(out, count, array.desc.type, false,
                             what + " at byte " + std::to_string(array.keywordOffset));
      return;
    }
    const LegacyType& type = array.type;
    if (!type.bit) {
      // In pieces that stay in the cache between reading and decoding; float32 in place.
      const std::uint64_t perPiece = kDecodeBytes / type.bytes;
      for (std::uint64_t done = 0; done < count;) {
        const std::uint64_t values = std::min(perPiece, count - done);
        const std::uint64_t at = array.offset + (first + done) * type.bytes, bytes = values * type.bytes;
        void* target = out + done;
        if (type.type != ValueType::Float32) {
          s.bytes.resize(bytes);
          target = s.bytes.data();
        }
        if (mFile.readAt(at, target, bytes) != bytes) truncated(what, at + bytes);
        if (type.type == ValueType::Float32)
          swapFloatsToNative(out + done, values, true);
        else
          decodeValues(type.type, true, s.bytes.data(), values, out + done);
        done += values;
      }
      return;
    }
    const std::uint64_t begin = first / 8, end = (first + count + 7) / 8;
    s.bytes.resize(end - begin);
    if (mFile.readAt(array.offset + begin, s.bytes.data(), s.bytes.size()) != s.bytes.size())
      truncated(what, array.offset + end);
    for (std::uint64_t i = 0; i < count; ++i) {  // bits, the first in the high bit of each byte
      const std::uint64_t bit = first + i - begin * 8;
      out[i] = float((std::uint8_t(s.bytes[bit / 8]) >> (7 - bit % 8)) & 1);
    }
  }

  [[noreturn]] void truncated(const std::string& what, std::uint64_t end) const {
    throw FileError(mFile.path(), "truncated: the file ends inside " + what + " (byte " + std::to_string(end) +
                                      "; it shrank since it was opened?)");
  }

  InputFile mFile;
  LegacyLayout mLayout;
  std::vector<AttributeDesc> mAttributes;
  std::vector<std::size_t> mSelected;
  std::optional<std::size_t> mVelocity;
  std::vector<Stream> mStreams;  ///< [0]: the positions
  std::size_t mVelocityStream = 0;
  std::vector<std::size_t> mColumnStreams;
  std::uint64_t mNext = 0;
};

}  // namespace

bool isVtkLegacy(std::span<const std::byte> head) {
  constexpr std::string_view kPrefix = "# vtk DataFile";
  return head.size() >= kPrefix.size() && std::memcmp(head.data(), kPrefix.data(), kPrefix.size()) == 0;
}

std::unique_ptr<ParticleSource> openVtkLegacyParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<VtkLegacyReader>(std::move(file), options);
}

}  // namespace flipscope::detail
