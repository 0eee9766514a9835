// VTK XML particle files (.vtu UnstructuredGrid, .vtp PolyData; described at docs.vtk.org, "VTK
// File Formats", XML section, and on the VTK wiki "VTK XML Formats"): the <Points> of every
// <Piece> and its <PointData> DataArrays. Data formats: ascii, binary (base64, inline) and
// appended (raw or base64 after the '_' of <AppendedData>), each array behind a header of
// header_type UInt32 or UInt64 (its byte count; with compressor="vtkZLibDataCompressor" the
// block table: #blocks, block size, last block size (0: a full block), compressed sizes, each
// block zlib-compressed on its own), in the file's byte_order. Cells, CellData and FieldData
// are skipped, String arrays too. Other dataset types (ImageData, RectilinearGrid,
// StructuredGrid) are grids, and the parallel P* files name pieces in other files: refused.
//
// Streaming: opening the file scans its XML once (inline array text is skipped with memchr to
// the next '<'; appended data is not read), recording where each array's data lies. read()
// then reads every array it needs through its own cursor, decoding base64 and zlib blocks as it
// goes: memory is bounded by the chunk plus one zlib block per array (at most 64 MiB each, a
// limit on the file's declared block size).
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>

#include "core/Error.h"
#include "preprocess/particles/Base64.h"
#include "preprocess/particles/FileCursor.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/ValueDecode.h"

namespace flipscope::detail {
namespace {

constexpr std::size_t kXmlCursorBytes = 256 << 10;
constexpr std::size_t kMaxTagBytes = 64 << 10;
constexpr std::size_t kStreamCursorBytes = 64 << 10;
constexpr std::size_t kAsciiCursorBytes = 256 << 10;
constexpr std::size_t kDecodeBytes = 256 << 10;  ///< binary values are decoded in pieces of this
constexpr std::uint64_t kMaxBlockBytes = 64 << 20;
constexpr std::uint64_t kMaxArity = 1 << 20;
/// zlib's largest expansion: 1032:1, plus a little for the stream header of tiny blocks.
constexpr std::uint64_t kMaxZlibRatio = 1032;

// ---- A small XML scanner: tags, their attributes, and where the text between them lies ----

struct XmlTag {
  enum class Kind { Start, End, Empty, Markup };  ///< Markup: a comment, declaration or DOCTYPE
  Kind kind = Kind::Start;
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::uint64_t offset = 0;  ///< of the '<'

  const std::string* find(std::string_view key) const {
    for (const auto& [k, v] : attributes)
      if (k == key) return &v;
    return nullptr;
  }
};

/// Text between two tags: [begin, end), end at the next '<' (or the end of the file); `data`
/// is the first byte that is not whitespace (== end when the text is blank).
struct XmlText {
  std::uint64_t begin = 0, data = 0, end = 0;
  bool blank() const { return data == end; }
};

class XmlScanner {
 public:
  explicit XmlScanner(InputFile& file) : mCursor(file, 0, file.size(), kXmlCursorBytes) {
    auto w = mCursor.window(3);
    if (w.size() >= 3 && std::memcmp(w.data(), "\xef\xbb\xbf", 3) == 0) mCursor.advance(3);  // UTF-8 BOM
  }
  FileCursor& cursor() { return mCursor; }
  [[noreturn]] void fail(const std::string& message) const { mCursor.fail("VTK XML: " + message); }

  /// Skips the text up to the next '<'.
  XmlText text() {
    XmlText t;
    t.begin = mCursor.offset();
    t.data = std::numeric_limits<std::uint64_t>::max();
    for (;;) {
      auto w = mCursor.window(1);
      if (w.empty()) break;
      std::size_t i = 0;
      if (t.data == std::numeric_limits<std::uint64_t>::max()) {
        while (i < w.size() && isSpaceByte(w[i])) ++i;
        if (i < w.size() && w[i] != '<') t.data = mCursor.offset() + i;
      }
      const auto* lt = static_cast<const char*>(std::memchr(w.data() + i, '<', w.size() - i));
      if (lt) {
        mCursor.advance(std::size_t(lt - w.data()));
        break;
      }
      mCursor.advance(w.size());
    }
    t.end = mCursor.offset();
    if (t.data > t.end) t.data = t.end;
    return t;
  }

  /// The next tag after `text()`; false at the end of the file. The XML declaration, processing
  /// instructions, comments and DOCTYPE come as Markup.
  bool tag(XmlTag& tag) {
    {
      if (mCursor.atEnd()) return false;
      auto w = mCursor.window(kMaxTagBytes + 1);
      FLIPSCOPE_CHECK(!w.empty() && w[0] == '<');
      tag.offset = mCursor.offset();
      std::string_view view(w.data(), w.size());
      if (view.substr(0, 2) == "<?" || view.substr(0, 4) == "<!--" || view.substr(0, 2) == "<!") {
        std::string_view close = view.substr(0, 2) == "<?" ? "?>" : view.substr(0, 4) == "<!--" ? "-->" : ">";
        std::size_t at = view.find(close, 2);
        if (at == std::string_view::npos) tooLongOrCut(w.size(), "a comment or declaration");
        mCursor.advance(at + close.size());
        tag.kind = XmlTag::Kind::Markup;
        tag.name.clear();
        tag.attributes.clear();
        return true;
      }
      std::size_t i = 1;
      tag.kind = XmlTag::Kind::Start;
      if (i < view.size() && view[i] == '/') {
        tag.kind = XmlTag::Kind::End;
        ++i;
      }
      tag.name = std::string(nameAt(view, i));
      if (tag.name.empty()) fail("malformed tag at byte " + std::to_string(tag.offset));
      tag.attributes.clear();
      for (;;) {
        while (i < view.size() && isSpaceByte(view[i])) ++i;
        if (i >= view.size()) tooLongOrCut(w.size(), "the tag <" + tag.name + ">");
        if (view[i] == '>') {
          ++i;
          break;
        }
        if (view[i] == '/' && tag.kind == XmlTag::Kind::Start) {
          if (i + 1 >= view.size()) tooLongOrCut(w.size(), "the tag <" + tag.name + ">");
          if (view[i + 1] != '>') fail("malformed tag <" + tag.name + "> at byte " + std::to_string(tag.offset));
          tag.kind = XmlTag::Kind::Empty;
          i += 2;
          break;
        }
        if (tag.kind == XmlTag::Kind::End)
          fail("malformed end tag </" + tag.name + "> at byte " + std::to_string(tag.offset));
        std::string key(nameAt(view, i));
        if (key.empty())
          fail("malformed attribute in <" + tag.name + "> at byte " + std::to_string(mCursor.offset() + i));
        while (i < view.size() && isSpaceByte(view[i])) ++i;
        if (i < view.size() && view[i] != '=')
          fail("attribute " + key + " of <" + tag.name + "> at byte " + std::to_string(tag.offset) + " has no value");
        ++i;
        while (i < view.size() && isSpaceByte(view[i])) ++i;
        if (i >= view.size()) tooLongOrCut(w.size(), "the tag <" + tag.name + ">");
        const char quote = view[i];
        if (quote != '"' && quote != '\'')
          fail("attribute " + key + " of <" + tag.name + "> at byte " + std::to_string(tag.offset) + " is not quoted");
        const std::size_t close = view.find(quote, i + 1);
        if (close == std::string_view::npos) tooLongOrCut(w.size(), "the tag <" + tag.name + ">");
        tag.attributes.emplace_back(std::move(key), unescape(view.substr(i + 1, close - i - 1)));
        i = close + 1;
      }
      mCursor.advance(i);
      return true;
    }
  }

 private:
  static std::string_view nameAt(std::string_view view, std::size_t& i) {
    const std::size_t start = i;
    while (i < view.size() && !isSpaceByte(view[i]) && view[i] != '>' && view[i] != '/' && view[i] != '=' &&
           view[i] != '<' && view[i] != '"' && view[i] != '\'')
      ++i;
    return view.substr(start, i - start);
  }
  [[noreturn]] void tooLongOrCut(std::size_t window, const std::string& what) const {
    if (window > kMaxTagBytes)
      fail(what + " at byte " + std::to_string(mCursor.offset()) + " is longer than " + std::to_string(kMaxTagBytes) +
           " bytes");
    fail("truncated: the file ends inside " + what + " at byte " + std::to_string(mCursor.offset()));
  }
  static std::string unescape(std::string_view text) {
    std::string out;
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] != '&') {
        out += text[i];
        continue;
      }
      const std::size_t semi = text.find(';', i);
      if (semi == std::string_view::npos || semi - i > 10) {
        out += text[i];
        continue;
      }
      std::string_view entity = text.substr(i + 1, semi - i - 1);
      static constexpr std::pair<std::string_view, char> kNamed[] = {
          {"lt", '<'}, {"gt", '>'}, {"amp", '&'}, {"quot", '"'}, {"apos", '\''}};
      bool known = false;
      for (auto [name, c] : kNamed)
        if (entity == name) {
          out += c;
          known = true;
        }
      if (!known && entity.size() > 1 && entity[0] == '#') {
        unsigned code = 0;
        const bool hex = entity[1] == 'x' || entity[1] == 'X';
        auto digits = entity.substr(hex ? 2 : 1);
        auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), code, hex ? 16 : 10);
        if (ec == std::errc() && end == digits.data() + digits.size() && code > 0 && code < 128) {
          out += char(code);
          known = true;
        }
      }
      if (!known) {
        out += text[i];
        continue;
      }
      i = semi;
    }
    return out;
  }

  FileCursor mCursor;
};

// ---- The layout: pieces, their arrays, and where the data lies ----

enum class DataFormat { Ascii, Binary, Appended };

struct XmlArray {
  std::string name;
  ValueType type = ValueType::Float32;
  int arity = 1;
  DataFormat format = DataFormat::Ascii;
  std::uint64_t appendedOffset = 0;  ///< format Appended: from the byte after '_'
  XmlText content;                   ///< inline formats
  std::uint64_t tagOffset = 0;
};

struct XmlPiece {
  std::uint64_t points = 0;
  std::uint64_t tagOffset = 0;
  std::optional<XmlArray> positions;
  std::vector<XmlArray> pointData;
};

struct XmlLayout {
  std::string type, version, byteOrder = "LittleEndian";
  bool bigEndian = false;
  std::size_t headerBytes = 4;
  bool zlib = false;
  bool appended = false;
  bool appendedBase64 = false;
  std::uint64_t appendedBegin = 0, appendedEnd = 0;  ///< [after '_', the '<' of </AppendedData>)
  std::vector<XmlPiece> pieces;
};

std::optional<ValueType> xmlType(const std::string& name) {
  static constexpr std::pair<std::string_view, ValueType> kTypes[] = {
      {"Int8", ValueType::Int8},       {"UInt8", ValueType::UInt8},   {"Int16", ValueType::Int16},
      {"UInt16", ValueType::UInt16},   {"Int32", ValueType::Int32},   {"UInt32", ValueType::UInt32},
      {"Int64", ValueType::Int64},     {"UInt64", ValueType::UInt64}, {"Float32", ValueType::Float32},
      {"Float64", ValueType::Float64}, {"Char", ValueType::Int8},     {"UChar", ValueType::UInt8}};
  for (auto [n, t] : kTypes)
    if (n == name) return t;
  return std::nullopt;
}

class XmlLayoutParser {
 public:
  explicit XmlLayoutParser(InputFile& file) : mFile(file), mScanner(file) {}

  XmlLayout parse() {
    XmlTag tag;
    do {
      if (!mScanner.text().blank()) fail("text before <VTKFile>");
      if (!mScanner.tag(tag)) fail("the file holds no XML element (expected <VTKFile>)");
    } while (tag.kind == XmlTag::Kind::Markup);
    if (tag.kind == XmlTag::Kind::End || tag.name != "VTKFile")
      fail("the root element is <" + tag.name.substr(0, 40) + ">, expected <VTKFile>");
    fileAttributes(tag);
    if (tag.kind == XmlTag::Kind::Empty) fail("<VTKFile> is empty: no points");
    mStack.push_back({"VTKFile", Role::File});
    bool closed = false;
    while (!closed) {
      const XmlText text = mScanner.text();
      if (!text.blank() && mStack.back().role == Role::Array) {
        if (mArray.content.end != 0)
          fail("the DataArray at byte " + std::to_string(mArray.tagOffset) + " holds its data in two parts");
        mArray.content = text;
      }
      if (!mScanner.tag(tag)) fail("truncated: the file ends inside <" + mStack.back().name + "> (no </VTKFile>)");
      if (tag.kind == XmlTag::Kind::Markup) continue;
      if (tag.kind == XmlTag::Kind::End) {
        if (tag.name != mStack.back().name)
          fail("</" + tag.name.substr(0, 40) + "> at byte " + std::to_string(tag.offset) + " closes <" +
               mStack.back().name + ">");
        if (mStack.size() >= 2) endElement(mStack.back().role, mStack[mStack.size() - 2].role);
        mStack.pop_back();
        closed = mStack.empty();
        continue;
      }
      if (tag.name == "AppendedData" && tag.kind == XmlTag::Kind::Start && mStack.back().role == Role::File) {
        appendedData(tag);
        break;
      }
      const Role role = childRole(tag);
      startElement(tag, role);
      if (tag.kind == XmlTag::Kind::Start)
        mStack.push_back({tag.name, role});
      else
        endElement(role, mStack.back().role);
    }
    if (closed) {  // after </VTKFile>: only whitespace and comments
      for (;;) {
        const XmlText text = mScanner.text();
        if (!text.blank()) fail("text after </VTKFile> at byte " + std::to_string(text.data));
        if (!mScanner.tag(tag)) break;
        if (tag.kind == XmlTag::Kind::Markup) continue;
        fail("<" + tag.name.substr(0, 40) + "> after </VTKFile> at byte " + std::to_string(tag.offset));
      }
    }
    if (mLayout.pieces.empty()) fail("the " + mLayout.type + " holds no <Piece>: no points");
    return std::move(mLayout);
  }

 private:
  enum class Role { File, Dataset, Piece, PointData, Points, Array, Skip };
  struct Frame {
    std::string name;
    Role role;
  };

  [[noreturn]] void fail(const std::string& message) const { mScanner.fail(message); }

  void fileAttributes(const XmlTag& tag) {
    const std::string* type = tag.find("type");
    if (!type) fail("<VTKFile> has no type attribute");
    mLayout.type = *type;
    if (*type != "UnstructuredGrid" && *type != "PolyData") {
      if (!type->empty() && (*type)[0] == 'P' && (*type == "PUnstructuredGrid" || *type == "PPolyData"))
        fail("the file is a parallel " + *type + ": it names piece files and holds no points itself (open the pieces)");
      const bool grid = *type == "ImageData" || *type == "RectilinearGrid" || *type == "StructuredGrid";
      fail("the dataset type is " + type->substr(0, 40) + (grid ? ", a grid" : "") +
           ", not particles (flipscope reads UnstructuredGrid and PolyData)");
    }
    if (const std::string* v = tag.find("version")) mLayout.version = v->substr(0, 20);
    if (const std::string* order = tag.find("byte_order")) {
      if (*order != "LittleEndian" && *order != "BigEndian")
        fail("byte_order '" + order->substr(0, 40) + "' (expected LittleEndian or BigEndian)");
      mLayout.byteOrder = *order;
      mLayout.bigEndian = *order == "BigEndian";
    }
    if (const std::string* header = tag.find("header_type")) {
      if (*header != "UInt32" && *header != "UInt64")
        fail("header_type '" + header->substr(0, 40) + "' (expected UInt32 or UInt64)");
      mLayout.headerBytes = *header == "UInt64" ? 8 : 4;
    }
    if (const std::string* compressor = tag.find("compressor"); compressor && !compressor->empty()) {
      if (*compressor != "vtkZLibDataCompressor")
        fail("compressor '" + compressor->substr(0, 40) + "' is not supported (only vtkZLibDataCompressor)");
      mLayout.zlib = true;
    }
  }

  Role childRole(const XmlTag& tag) const {
    const Role parent = mStack.back().role;
    if (parent == Role::File && tag.name == mLayout.type) return Role::Dataset;
    if (parent == Role::Dataset && tag.name == "Piece") return Role::Piece;
    if (parent == Role::Piece && tag.name == "PointData") return Role::PointData;
    if (parent == Role::Piece && tag.name == "Points") return Role::Points;
    if ((parent == Role::PointData || parent == Role::Points) && tag.name == "DataArray") return Role::Array;
    return Role::Skip;
  }

  std::uint64_t number(const XmlTag& tag, const char* key, std::optional<std::uint64_t> fallback) const {
    const std::string* text = tag.find(key);
    if (!text) {
      if (fallback) return *fallback;
      fail("<" + tag.name + "> at byte " + std::to_string(tag.offset) + " has no " + key);
    }
    std::uint64_t value = 0;
    auto [end, ec] = std::from_chars(text->data(), text->data() + text->size(), value);
    if (ec != std::errc() || end != text->data() + text->size())
      fail("malformed " + std::string(key) + " '" + text->substr(0, 40) + "' of <" + tag.name + "> at byte " +
           std::to_string(tag.offset));
    return value;
  }

  void startElement(const XmlTag& tag, Role role) {
    if (role == Role::Piece) {
      XmlPiece piece;
      piece.points = number(tag, "NumberOfPoints", std::nullopt);
      piece.tagOffset = tag.offset;
      mLayout.pieces.push_back(std::move(piece));
    } else if (role == Role::Array) {
      mArray = XmlArray{};
      mArray.tagOffset = tag.offset;
      const std::string where = "the DataArray at byte " + std::to_string(tag.offset);
      if (const std::string* name = tag.find("Name")) mArray.name = *name;
      const std::string* type = tag.find("type");
      if (!type) fail(where + " has no type");
      mSkipArray = false;
      if (*type == "String") {
        mSkipArray = mStack.back().role == Role::PointData;
        if (!mSkipArray) fail(where + " (the points) holds strings");
      } else if (auto t = xmlType(*type)) {
        mArray.type = *t;
      } else {
        fail(where + " has an unknown type '" + type->substr(0, 40) + "'");
      }
      const std::uint64_t arity = number(tag, "NumberOfComponents", 1);
      if (arity == 0 || arity > kMaxArity)
        fail(where + ": NumberOfComponents " + std::to_string(arity) + " is out of range (1 to " +
             std::to_string(kMaxArity) + ")");
      mArray.arity = int(arity);
      const std::string* format = tag.find("format");
      if (!format) fail(where + " has no format");
      if (*format == "ascii")
        mArray.format = DataFormat::Ascii;
      else if (*format == "binary")
        mArray.format = DataFormat::Binary;
      else if (*format == "appended")
        mArray.format = DataFormat::Appended;
      else
        fail(where + " has an unknown format '" + format->substr(0, 40) + "' (expected ascii, binary or appended)");
      if (mArray.format == DataFormat::Appended) mArray.appendedOffset = number(tag, "offset", std::nullopt);
    }
  }

  /// The end of an element of `role` inside one of `parent`.
  void endElement(Role role, Role parent) {
    if (role != Role::Array || mSkipArray) return;
    XmlPiece& piece = mLayout.pieces.back();
    if (parent == Role::Points) {
      if (piece.positions)
        fail("the <Points> of the <Piece> at byte " + std::to_string(piece.tagOffset) + " hold two DataArrays");
      if (mArray.arity != 3)
        fail("the points DataArray at byte " + std::to_string(mArray.tagOffset) + " has " +
             std::to_string(mArray.arity) + " components, expected 3");
      piece.positions = mArray;
    } else {
      piece.pointData.push_back(mArray);
    }
  }

  void appendedData(const XmlTag& tag) {
    const std::string* encoding = tag.find("encoding");
    if (!encoding || (*encoding != "raw" && *encoding != "base64"))
      fail("<AppendedData> at byte " + std::to_string(tag.offset) + " has encoding '" +
           (encoding ? encoding->substr(0, 40) : std::string()) + "' (expected raw or base64)");
    mLayout.appended = true;
    mLayout.appendedBase64 = *encoding == "base64";
    FileCursor& cursor = mScanner.cursor();
    while (cursor.peek() >= 0 && isSpaceByte(char(cursor.peek()))) cursor.advance(1);
    if (cursor.peek() != '_')
      fail("<AppendedData> at byte " + std::to_string(tag.offset) + ": expected '_' before the data at byte " +
           std::to_string(cursor.offset()));
    mLayout.appendedBegin = cursor.offset() + 1;
    // The data is not XML: the file must end with </AppendedData> </VTKFile>.
    const std::uint64_t size = mFile.size();
    const std::uint64_t tailStart = size - std::min<std::uint64_t>(size, 4096);
    std::string tail(std::size_t(size - tailStart), '\0');
    if (mFile.readAt(tailStart, tail.data(), tail.size()) != tail.size()) fail("the file shrank while opening it");
    auto trimEnd = [&](std::size_t end) {
      while (end > 0 && isSpaceByte(tail[end - 1])) --end;
      return end;
    };
    std::size_t end = trimEnd(tail.size());
    constexpr std::string_view kFileEnd = "</VTKFile>", kDataEnd = "</AppendedData>";
    bool ok =
        end >= kFileEnd.size() && std::string_view(tail).substr(end - kFileEnd.size(), kFileEnd.size()) == kFileEnd;
    if (ok) {
      end = trimEnd(end - kFileEnd.size());
      ok = end >= kDataEnd.size() && std::string_view(tail).substr(end - kDataEnd.size(), kDataEnd.size()) == kDataEnd;
    }
    if (!ok || tailStart + end - kDataEnd.size() < mLayout.appendedBegin)
      fail("truncated: the file does not end with </AppendedData></VTKFile> (appended data from byte " +
           std::to_string(mLayout.appendedBegin) + ", file size " + std::to_string(size) + ")");
    mLayout.appendedEnd = tailStart + end - kDataEnd.size();
  }

  InputFile& mFile;
  XmlScanner mScanner;
  XmlLayout mLayout;
  std::vector<Frame> mStack;
  XmlArray mArray;  ///< the DataArray being read
  bool mSkipArray = false;
};

// ---- One array's values, read in order ----

class ArrayStream {
 public:
  ArrayStream(InputFile& file, const XmlLayout& layout, const XmlArray& array, std::uint64_t tuples, std::string what)
      : mPath(file.path()), mLayout(layout), mArray(array), mWhat(std::move(what)) {
    if (tuples > std::numeric_limits<std::uint64_t>::max() / std::uint64_t(array.arity)) fail("too many values");
    mValues = tuples * std::uint64_t(array.arity);
    if (array.format == DataFormat::Ascii) {
      mCursor = std::make_unique<FileCursor>(file, array.content.data, array.content.end, kAsciiCursorBytes);
      return;
    }
    std::uint64_t begin = 0, end = 0;
    bool base64 = array.format == DataFormat::Binary;
    if (array.format == DataFormat::Binary) {
      begin = array.content.data;
      end = array.content.end;
    } else {
      if (!layout.appended)
        fail("is appended, but the file has no <AppendedData> (DataArray at byte " + std::to_string(array.tagOffset) +
             ")");
      base64 = layout.appendedBase64;
      const std::uint64_t span = layout.appendedEnd - layout.appendedBegin;
      if (array.appendedOffset > span)
        fail("starts at appended offset " + std::to_string(array.appendedOffset) + ", past the end of the " +
             std::to_string(span) + " appended bytes");
      begin = layout.appendedBegin + array.appendedOffset;
      end = layout.appendedEnd;
    }
    mCursor = std::make_unique<FileCursor>(file, begin, end, kStreamCursorBytes);
    if (base64) mBase64 = std::make_unique<Base64Reader>(*mCursor);
    readHeader();
  }

  /// The next `count` values, converted to float.
  void read(float* out, std::size_t count) {
    if (mArray.format == DataFormat::Ascii) {
      mCursor->parseNumbers(out, count, mArray.type, true, mWhat);
      return;
    }
    // In pieces that stay in the cache between reading and decoding; float32 in place.
    const std::size_t size = valueTypeBytes(mArray.type), perPiece = kDecodeBytes / size;
    for (std::size_t done = 0; done < count;) {
      const std::size_t values = std::min(perPiece, count - done);
      if (mArray.type == ValueType::Float32) {
        payload(reinterpret_cast<std::byte*>(out + done), values * size);
        swapFloatsToNative(out + done, values, mLayout.bigEndian);
      } else {
        mScratch.resize(values * size);
        payload(mScratch.data(), values * size);
        decodeValues(mArray.type, mLayout.bigEndian, mScratch.data(), values, out + done);
      }
      done += values;
    }
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw FileError(mPath, "VTK XML: " + mWhat + " " + message);
  }

  /// The next `bytes` bytes of the values (decompressed).
  void payload(std::byte* out, std::size_t bytes) {
    if (!mLayout.zlib) {
      readBytes(out, bytes, "the values");
      return;
    }
    for (std::size_t done = 0; done < bytes;) {
      if (mBlockAt == mBlock.size()) nextBlock();
      const std::size_t n = std::min(bytes - done, mBlock.size() - mBlockAt);
      std::memcpy(out + done, mBlock.data() + mBlockAt, n);
      mBlockAt += n;
      done += n;
    }
  }

  void readBytes(std::byte* out, std::size_t bytes, const char* part) {
    const std::string what = std::string(part) + " of " + mWhat;
    if (mBase64)
      mBase64->read(out, bytes, what);
    else
      mCursor->readExact(out, bytes, what);
  }
  std::uint64_t bytesLeft() const { return mBase64 ? mBase64->maxRemaining() : mCursor->remaining(); }

  std::uint64_t headerValue() {
    std::byte bytes[8];
    readBytes(bytes, mLayout.headerBytes, "the header");
    return decodeUnsigned(bytes, mLayout.headerBytes, mLayout.bigEndian);
  }

  void readHeader() {
    const std::uint64_t size = valueTypeBytes(mArray.type);
    if (mValues > std::numeric_limits<std::uint64_t>::max() / size) fail("holds too many values");
    const std::uint64_t expected = mValues * size;
    if (!mLayout.zlib) {
      const std::uint64_t declared = headerValue();
      if (declared != expected)
        fail("declares " + std::to_string(declared) + " bytes in its header, expected " + std::to_string(expected) +
             " (" + std::to_string(mValues) + " values of " + std::string(valueTypeName(mArray.type)) + ")");
      if (expected > bytesLeft())
        fail("is truncated: " + std::to_string(expected) + " bytes declared, at most " + std::to_string(bytesLeft()) +
             " left");
      return;
    }
    const std::uint64_t blocks = headerValue();
    mBlockSize = headerValue();
    const std::uint64_t last = headerValue();
    mLastSize = last == 0 ? mBlockSize : last;
    if (blocks == 0) {
      if (expected != 0) fail("has no zlib blocks, expected " + std::to_string(expected) + " bytes");
      return;
    }
    if (mBlockSize == 0 || last > mBlockSize)
      fail("has a malformed zlib header (block size " + std::to_string(mBlockSize) + ", last block " +
           std::to_string(last) + ")");
    if (mBlockSize > kMaxBlockBytes)
      fail("has zlib blocks of " + std::to_string(mBlockSize) + " bytes, more than the " +
           std::to_string(kMaxBlockBytes) + " flipscope reads");
    if (blocks - 1 > (std::numeric_limits<std::uint64_t>::max() - mLastSize) / mBlockSize ||
        (blocks - 1) * mBlockSize + mLastSize != expected)
      fail("has " + std::to_string(blocks) + " zlib blocks of " + std::to_string(mBlockSize) + " bytes (last " +
           std::to_string(mLastSize) + "), expected " + std::to_string(expected) + " bytes in all");
    if (blocks > bytesLeft() / mLayout.headerBytes)
      fail("is truncated: its header declares " + std::to_string(blocks) + " zlib blocks");
    mCompressedSizes.resize(blocks);
    std::uint64_t total = 0;
    for (auto& s : mCompressedSizes) {
      s = headerValue();
      total =
          s > std::numeric_limits<std::uint64_t>::max() - total ? std::numeric_limits<std::uint64_t>::max() : total + s;
    }
    if (total > bytesLeft())
      fail("is truncated: its zlib blocks take " + std::to_string(total) + " bytes, at most " +
           std::to_string(bytesLeft()) + " are left");
  }

  void nextBlock() {
    if (mNextBlock >= mCompressedSizes.size()) fail("holds fewer bytes than its values need");
    const std::size_t index = mNextBlock++;
    const std::uint64_t usize = index + 1 == mCompressedSizes.size() ? mLastSize : mBlockSize;
    const std::uint64_t csize = mCompressedSizes[index];
    const std::string block = "zlib block " + std::to_string(index) + " of " + std::to_string(mCompressedSizes.size());
    if (usize > csize * kMaxZlibRatio + 64)
      fail(block + ": " + std::to_string(csize) + " compressed bytes cannot hold " + std::to_string(usize));
    mCompressed.resize(csize);
    readBytes(mCompressed.data(), csize, block.c_str());
    mBlock.resize(usize);
    uLongf length = uLongf(usize);
    const int rc = ::uncompress(reinterpret_cast<Bytef*>(mBlock.data()), &length,
                                reinterpret_cast<const Bytef*>(mCompressed.data()), uLong(csize));
    if (rc != Z_OK || length != usize)
      fail(block + " is damaged (zlib: " +
           (rc == Z_OK ? "decodes to " + std::to_string(length) + " bytes, expected " + std::to_string(usize)
                       : std::string(zError(rc))) +
           ")");
    mBlockAt = 0;
  }

  std::filesystem::path mPath;
  const XmlLayout& mLayout;
  const XmlArray& mArray;
  std::string mWhat;
  std::uint64_t mValues = 0;
  std::unique_ptr<FileCursor> mCursor;
  std::unique_ptr<Base64Reader> mBase64;
  std::vector<std::byte> mScratch;
  // zlib
  std::uint64_t mBlockSize = 0, mLastSize = 0;
  std::vector<std::uint64_t> mCompressedSizes;
  std::size_t mNextBlock = 0;
  std::vector<std::byte> mCompressed, mBlock;
  std::size_t mBlockAt = 0;
};

std::string formatName(DataFormat format, const XmlLayout& layout) {
  switch (format) {
    case DataFormat::Ascii:
      return "ascii";
    case DataFormat::Binary:
      return "binary";
    case DataFormat::Appended:
      return layout.appendedBase64 ? "appended base64" : "appended raw";
  }
  return "";
}

class VtkXmlReader final : public ParticleSource {
 public:
  VtkXmlReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    mLayout = XmlLayoutParser(mFile).parse();
    const XmlPiece& first = mLayout.pieces.front();
    for (const auto& array : first.pointData) {
      if (array.name.empty())
        throw FileError(mFile.path(),
                        "VTK XML: the point DataArray at byte " + std::to_string(array.tagOffset) + " has no Name");
      mAttributes.push_back({array.name, array.type, array.arity});
    }
    for (const XmlPiece& piece : mLayout.pieces) {
      if (piece.points > std::numeric_limits<std::uint64_t>::max() - mCount)
        throw FileError(mFile.path(), "VTK XML: the pieces hold more than 2^64 points");
      mCount += piece.points;
      if (piece.points > 0 && !piece.positions)
        throw FileError(mFile.path(), "VTK XML: the <Piece> at byte " + std::to_string(piece.tagOffset) + " has " +
                                          std::to_string(piece.points) + " points but no <Points> DataArray");
      std::vector<std::size_t> map;
      for (const auto& attribute : mAttributes) {
        auto found = std::find_if(piece.pointData.begin(), piece.pointData.end(),
                                  [&](const XmlArray& a) { return a.name == attribute.name; });
        if (found == piece.pointData.end() || found->arity != attribute.arity)
          throw FileError(mFile.path(), "VTK XML: the <Piece> at byte " + std::to_string(piece.tagOffset) +
                                            " has no point array '" + attribute.name + "' with " +
                                            std::to_string(attribute.arity) + " components, as the first piece has");
        map.push_back(std::size_t(found - piece.pointData.begin()));
      }
      mPieceArrays.push_back(std::move(map));
      if (piece.positions) mFormats.push_back(piece.positions->format);
      for (const auto& a : piece.pointData) mFormats.push_back(a.format);
    }
    std::sort(mFormats.begin(), mFormats.end());
    mFormats.erase(std::unique(mFormats.begin(), mFormats.end()), mFormats.end());
    mSelected = selectAttributes(mAttributes, options, mFile.path());
    if (options.velocity) mVelocity = velocityAttributeByName(mAttributes);
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    std::string formats;
    for (DataFormat f : mFormats) formats += (formats.empty() ? "" : ", ") + formatName(f, mLayout);
    if (formats.empty()) formats = "no data";
    return "VTK XML " + mLayout.type + (mLayout.version.empty() ? "" : " " + mLayout.version) + " (" + formats +
           (mLayout.zlib ? ", zlib" : "") + ", " + (mLayout.headerBytes == 8 ? "UInt64" : "UInt32") + " headers, " +
           mLayout.byteOrder + ", " + std::to_string(mLayout.pieces.size()) +
           (mLayout.pieces.size() == 1 ? " piece)" : " pieces)");
  }
  std::vector<AttributeDesc> attributes() const override { return mAttributes; }
  bool hasVelocity() const override { return mVelocity.has_value(); }
  std::optional<std::uint64_t> countHint() const override { return mCount; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    while (mPiece < mLayout.pieces.size() && mInPiece == mLayout.pieces[mPiece].points) {
      ++mPiece;
      mInPiece = 0;
      mStreams.clear();
    }
    if (mPiece == mLayout.pieces.size()) {
      chunk.clear();
      chunk.attributes.clear();
      return false;
    }
    if (mStreams.empty()) openStreams();
    const XmlPiece& piece = mLayout.pieces[mPiece];
    const std::uint64_t n = std::min<std::uint64_t>(maxParticles, piece.points - mInPiece);
    const detail::FloatStreams streams{mStreams.size(), mVelocity.has_value(), mVelocityStream, mColumnStreams};
    detail::fillFromFloatStreams(
        chunk, std::size_t(n), streams, mAttributes, mSelected,
        [&](std::size_t stream) { return int(mStreams[stream].arity); },
        [&](std::size_t stream, std::size_t count, float* out) { mStreams[stream].stream->read(out, count * std::size_t(mStreams[stream].arity)); });
    mInPiece += n;
    return true;
  }

  void rewind() override {
    mPiece = 0;
    mInPiece = 0;
    mStreams.clear();
  }

 private:
  struct Stream {
    const XmlArray* array;
    int arity;
    std::unique_ptr<ArrayStream> stream;
  };

  std::size_t addStream(const XmlArray& array, const std::string& what) {
    for (std::size_t i = 0; i < mStreams.size(); ++i)
      if (mStreams[i].array == &array) return i;
    const XmlPiece& piece = mLayout.pieces[mPiece];
    mStreams.push_back({&array, array.arity, std::make_unique<ArrayStream>(mFile, mLayout, array, piece.points, what)});
    return mStreams.size() - 1;
  }

  void openStreams() {
    const XmlPiece& piece = mLayout.pieces[mPiece];
    const std::string of = " of the <Piece> at byte " + std::to_string(piece.tagOffset);
    addStream(*piece.positions, "the points" + of);
    auto attribute = [&](std::size_t index) -> std::size_t {
      const XmlArray& array = piece.pointData[mPieceArrays[mPiece][index]];
      return addStream(array, "point array '" + array.name + "'" + of);
    };
    if (mVelocity) mVelocityStream = attribute(*mVelocity);
    mColumnStreams.clear();
    for (std::size_t index : mSelected) mColumnStreams.push_back(attribute(index));
  }

  InputFile mFile;
  XmlLayout mLayout;
  std::vector<AttributeDesc> mAttributes;
  std::vector<std::vector<std::size_t>> mPieceArrays;  ///< per piece: attribute -> index in its pointData
  std::vector<DataFormat> mFormats;
  std::vector<std::size_t> mSelected;
  std::optional<std::size_t> mVelocity;
  std::uint64_t mCount = 0;
  std::size_t mPiece = 0;
  std::uint64_t mInPiece = 0;
  std::vector<Stream> mStreams;  ///< of the current piece; [0]: the points
  std::size_t mVelocityStream = 0;
  std::vector<std::size_t> mColumnStreams;
};

}  // namespace

bool isVtkXml(std::span<const std::byte> head) {
  std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
  if (text.substr(0, 3) == "\xef\xbb\xbf") text.remove_prefix(3);
  while (!text.empty() && isSpaceByte(text.front())) text.remove_prefix(1);
  if (text.substr(0, 8) == "<VTKFile") return true;
  return text.substr(0, 5) == "<?xml" && text.find("<VTKFile") != std::string_view::npos;
}

std::unique_ptr<ParticleSource> openVtkXmlParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<VtkXmlReader>(std::move(file), options);
}

}  // namespace flipscope::detail
