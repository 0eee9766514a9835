// Test writers for VTK particle files, written from the format descriptions (not by VTK): the
// legacy format (ASCII or BINARY, POLYDATA or UNSTRUCTURED_GRID, versions 4.x and 5.x cells,
// SCALARS / COLOR_SCALARS / VECTORS / NORMALS / FIELD arrays of any type) and the XML format
// (.vtu/.vtp: ascii, inline base64, appended raw or base64, zlib blocks or none, UInt32 or
// UInt64 headers, either byte order, several pieces). For round trips of the readers
// (VtkLegacyParticles.cpp, VtuParticles.cpp) and their fuzz seeds.
#pragma once

#include <zlib.h>

#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "preprocess/particles/ParticleSource.h"

namespace flipscope::testing {

/// One point-data array: `values` holds points × arity values, each representable in `type`.
struct VtkTestArray {
  enum class Kind { Scalars, ColorScalars, Vectors, Normals, TextureCoordinates, Field };
  std::string name;
  ValueType type = ValueType::Float32;
  int arity = 1;
  std::vector<double> values;
  Kind kind = Kind::Field;
  /// Legacy type name instead of the one of `type` ("long", "vtkIdType", "bit").
  std::string legacyTypeName;
};

namespace vtk_writer {

inline std::string legacyTypeName(ValueType type) {
  switch (type) {
    case ValueType::Int8:
      return "char";
    case ValueType::UInt8:
      return "unsigned_char";
    case ValueType::Int16:
      return "short";
    case ValueType::UInt16:
      return "unsigned_short";
    case ValueType::Int32:
      return "int";
    case ValueType::UInt32:
      return "unsigned_int";
    case ValueType::Int64:
      return "vtktypeint64";
    case ValueType::UInt64:
      return "vtktypeuint64";
    case ValueType::Float32:
      return "float";
    case ValueType::Float64:
      return "double";
    default:
      throw std::logic_error("no legacy VTK type for this ValueType");
  }
}

inline std::string xmlTypeName(ValueType type) {
  switch (type) {
    case ValueType::Int8:
      return "Int8";
    case ValueType::UInt8:
      return "UInt8";
    case ValueType::Int16:
      return "Int16";
    case ValueType::UInt16:
      return "UInt16";
    case ValueType::Int32:
      return "Int32";
    case ValueType::UInt32:
      return "UInt32";
    case ValueType::Int64:
      return "Int64";
    case ValueType::UInt64:
      return "UInt64";
    case ValueType::Float32:
      return "Float32";
    case ValueType::Float64:
      return "Float64";
    default:
      throw std::logic_error("no VTK XML type for this ValueType");
  }
}

inline std::size_t typeBytes(ValueType type) {
  switch (type) {
    case ValueType::Int8:
    case ValueType::UInt8:
      return 1;
    case ValueType::Int16:
    case ValueType::UInt16:
      return 2;
    case ValueType::Int32:
    case ValueType::UInt32:
    case ValueType::Float32:
      return 4;
    default:
      return 8;
  }
}

template <class T>
void appendValue(std::string& out, T value, bool bigEndian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (bigEndian != (std::endian::native == std::endian::big))
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  out.append(bytes, sizeof(T));
}

/// `value` as `type`, in binary.
inline void appendBinary(std::string& out, ValueType type, double value, bool bigEndian) {
  switch (type) {
    case ValueType::Int8:
      return appendValue(out, std::int8_t(value), bigEndian);
    case ValueType::UInt8:
      return appendValue(out, std::uint8_t(value), bigEndian);
    case ValueType::Int16:
      return appendValue(out, std::int16_t(value), bigEndian);
    case ValueType::UInt16:
      return appendValue(out, std::uint16_t(value), bigEndian);
    case ValueType::Int32:
      return appendValue(out, std::int32_t(value), bigEndian);
    case ValueType::UInt32:
      return appendValue(out, std::uint32_t(value), bigEndian);
    case ValueType::Int64:
      return appendValue(out, std::int64_t(value), bigEndian);
    case ValueType::UInt64:
      return appendValue(out, std::uint64_t(value), bigEndian);
    case ValueType::Float32:
      return appendValue(out, float(value), bigEndian);
    default:
      return appendValue(out, value, bigEndian);
  }
}

/// `value` as `type`, in text (the shortest form that reads back the same value).
inline void appendText(std::string& out, ValueType type, double value) {
  char text[64];
  char* end = type == ValueType::Float32   ? std::to_chars(text, text + sizeof text, float(value)).ptr
              : type == ValueType::Float64 ? std::to_chars(text, text + sizeof text, value).ptr
                                           : std::to_chars(text, text + sizeof text, std::int64_t(value)).ptr;
  if (type == ValueType::UInt64) end = std::to_chars(text, text + sizeof text, std::uint64_t(value)).ptr;
  out.append(text, end);
}

inline void appendTextValues(std::string& out, ValueType type, const std::vector<double>& values, int perLine) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    appendText(out, type, values[i]);
    out += (i + 1) % std::size_t(perLine) == 0 || i + 1 == values.size() ? '\n' : ' ';
  }
}

inline std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16 |
                            std::uint32_t(std::uint8_t(bytes[i + 1])) << 8 | std::uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace vtk_writer

// ---- Legacy .vtk ----

struct LegacyVtkOptions {
  bool binary = true;
  bool polydata = false;        ///< else UNSTRUCTURED_GRID
  std::string version = "4.1";  ///< "5.1": cells as OFFSETS and CONNECTIVITY
  ValueType pointType = ValueType::Float32;
  bool cells = true;          ///< one vertex cell per point (VERTICES or CELLS + CELL_TYPES)
  bool cellData = false;      ///< a CELL_DATA section, to be skipped
  bool datasetField = false;  ///< dataset FIELD data before the points, to be skipped
  bool metadata = false;      ///< METADATA blocks after arrays
  std::string title = "flipscope test";
};

inline std::string legacyVtk(const std::vector<double>& xyz, const std::vector<VtkTestArray>& arrays,
                             const LegacyVtkOptions& options) {
  using namespace vtk_writer;
  const std::size_t n = xyz.size() / 3;
  std::string out = "# vtk DataFile Version " + options.version + "\n" + options.title + "\n" +
                    (options.binary ? "BINARY\n" : "ASCII\n") +
                    (options.polydata ? "DATASET POLYDATA\n" : "DATASET UNSTRUCTURED_GRID\n");
  auto values = [&](ValueType type, const std::vector<double>& v, const std::string& typeName = "") {
    if (typeName == "bit") {
      if (options.binary) {
        std::string bits((v.size() + 7) / 8, '\0');
        for (std::size_t i = 0; i < v.size(); ++i)
          if (v[i] != 0) bits[i / 8] = char(std::uint8_t(bits[i / 8]) | (0x80 >> (i % 8)));
        out += bits;
        out += '\n';
      } else {
        appendTextValues(out, ValueType::UInt8, v, 9);
      }
      return;
    }
    ValueType stored = type;
    if (typeName == "long") stored = ValueType::Int64;
    if (typeName == "vtkIdType") stored = ValueType::Int32;
    if (options.binary) {
      for (double x : v) appendBinary(out, stored, x, true);
      out += '\n';
    } else {
      appendTextValues(out, stored, v, 9);
    }
  };
  auto metadata = [&] {
    if (options.metadata) out += "METADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 1\n\n";
  };
  if (options.datasetField) {
    out += "FIELD FieldData 2\nTIME 1 1 double\n";
    values(ValueType::Float64, {0.25});
    out += "CYCLE 1 1 int\n";
    values(ValueType::Int32, {7});
  }
  out += "POINTS " + std::to_string(n) + " " + legacyTypeName(options.pointType) + "\n";
  values(options.pointType, xyz);
  metadata();
  const bool v5 = options.version[0] >= '5';
  if (options.cells) {
    std::vector<double> offsets, connectivity, legacy, types;
    for (std::size_t i = 0; i <= n; ++i) offsets.push_back(double(i));
    for (std::size_t i = 0; i < n; ++i) {
      connectivity.push_back(double(i));
      legacy.push_back(1);
      legacy.push_back(double(i));
      types.push_back(1);
    }
    const std::string keyword = options.polydata ? "VERTICES " : "CELLS ";
    if (v5) {
      out += keyword + std::to_string(n + 1) + " " + std::to_string(n) + "\nOFFSETS vtktypeint64\n";
      values(ValueType::Int64, offsets);
      out += "CONNECTIVITY vtktypeint64\n";
      values(ValueType::Int64, connectivity);
    } else {
      out += keyword + std::to_string(n) + " " + std::to_string(2 * n) + "\n";
      values(ValueType::Int32, legacy);
    }
    if (!options.polydata) {
      out += "CELL_TYPES " + std::to_string(n) + "\n";
      values(ValueType::Int32, types);
    }
    if (options.cellData) {
      out += "CELL_DATA " + std::to_string(n) + "\nSCALARS cell_id int 1\nLOOKUP_TABLE default\n";
      values(ValueType::Int32, connectivity);
      out += "VECTORS cell_vector float\n";
      std::vector<double> v(3 * n, 0.5);
      values(ValueType::Float32, v);
      out += "FIELD FieldData 1\ncell_field 2 " + std::to_string(n) + " double\n";
      std::vector<double> f(2 * n, -1.5);
      values(ValueType::Float64, f);
      metadata();
    }
  }
  if (arrays.empty()) return out;
  out += "POINT_DATA " + std::to_string(n) + "\n";
  std::vector<const VtkTestArray*> fields;
  for (const auto& a : arrays) {
    const std::string type = a.legacyTypeName.empty() ? legacyTypeName(a.type) : a.legacyTypeName;
    switch (a.kind) {
      case VtkTestArray::Kind::Scalars:
        out += "SCALARS " + a.name + " " + type + " " + std::to_string(a.arity) + "\nLOOKUP_TABLE default\n";
        break;
      case VtkTestArray::Kind::ColorScalars:
        out += "COLOR_SCALARS " + a.name + " " + std::to_string(a.arity) + "\n";
        break;
      case VtkTestArray::Kind::Vectors:
        out += "VECTORS " + a.name + " " + type + "\n";
        break;
      case VtkTestArray::Kind::Normals:
        out += "NORMALS " + a.name + " " + type + "\n";
        break;
      case VtkTestArray::Kind::TextureCoordinates:
        out += "TEXTURE_COORDINATES " + a.name + " " + std::to_string(a.arity) + " " + type + "\n";
        break;
      case VtkTestArray::Kind::Field:
        fields.push_back(&a);
        continue;
    }
    if (a.kind == VtkTestArray::Kind::ColorScalars)
      values(options.binary ? ValueType::UInt8 : ValueType::Float32, a.values);
    else
      values(a.type, a.values, a.legacyTypeName);
    metadata();
  }
  if (!fields.empty()) {
    out += "FIELD FieldData " + std::to_string(fields.size()) + "\n";
    for (const VtkTestArray* a : fields) {
      const std::string type = a->legacyTypeName.empty() ? legacyTypeName(a->type) : a->legacyTypeName;
      out += a->name + " " + std::to_string(a->arity) + " " + std::to_string(n) + " " + type + "\n";
      values(a->type, a->values, a->legacyTypeName);
      metadata();
    }
  }
  return out;
}

// ---- XML .vtu / .vtp ----

struct VtuOptions {
  enum class Data { Ascii, Binary, AppendedRaw, AppendedBase64 };
  Data data = Data::AppendedRaw;
  bool zlib = false;
  bool header64 = false;
  bool bigEndian = false;
  ValueType pointType = ValueType::Float32;
  int pieces = 1;
  std::size_t blockSize = 32768;
  bool polyData = false;
  bool cells = true;        ///< cells (or verts) arrays and a CellData array, to be skipped
  bool headerApart = true;  ///< base64: the header encoded apart from the data, as VTK does
  bool fieldData = false;   ///< dataset FieldData, to be skipped
};

inline std::string vtu(const std::vector<double>& xyz, const std::vector<VtkTestArray>& arrays,
                       const VtuOptions& options) {
  using namespace vtk_writer;
  using Data = VtuOptions::Data;
  const std::string type = options.polyData ? "PolyData" : "UnstructuredGrid";
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" + type + "\" version=\"1.0\" byte_order=\"" +
                    (options.bigEndian ? "BigEndian" : "LittleEndian") + "\" header_type=\"" +
                    (options.header64 ? "UInt64" : "UInt32") + "\"" +
                    (options.zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") + ">\n  <" + type + ">\n";
  std::string appended;
  auto header = [&](std::uint64_t v, std::string& to) {
    if (options.header64)
      appendValue(to, v, options.bigEndian);
    else
      appendValue(to, std::uint32_t(v), options.bigEndian);
  };
  // One DataArray element for `values` of `valueType`.
  auto dataArray = [&](const std::string& attributes, ValueType valueType, int arity,
                       const std::vector<double>& values) {
    std::string element = "<DataArray type=\"" + xmlTypeName(valueType) + "\"" + attributes + " NumberOfComponents=\"" +
                          std::to_string(arity) + "\" format=\"";
    if (options.data == Data::Ascii) {
      element += "ascii\">\n";
      appendTextValues(element, valueType, values, 6);
      return element + "</DataArray>\n";
    }
    std::string raw;
    for (double v : values) appendBinary(raw, valueType, v, options.bigEndian);
    std::string head, body;
    if (!options.zlib) {
      header(raw.size(), head);
      body = raw;
    } else {
      std::vector<std::string> blocks;
      for (std::size_t at = 0; at < raw.size(); at += options.blockSize) {
        const std::string block = raw.substr(at, options.blockSize);
        uLongf length = compressBound(uLong(block.size()));
        std::string compressed(length, '\0');
        if (compress2(reinterpret_cast<Bytef*>(compressed.data()), &length,
                      reinterpret_cast<const Bytef*>(block.data()), uLong(block.size()), 6) != Z_OK)
          throw std::runtime_error("compress2 failed");
        compressed.resize(length);
        blocks.push_back(compressed);
      }
      header(blocks.size(), head);
      header(options.blockSize, head);
      header(raw.size() % options.blockSize, head);
      for (const auto& b : blocks) header(b.size(), head);
      for (const auto& b : blocks) body += b;
    }
    const std::string encoded = options.headerApart ? base64(head) + base64(body) : base64(head + body);
    if (options.data == Data::Binary) return element + "binary\">\n" + encoded + "\n</DataArray>\n";
    element += "appended\" offset=\"" + std::to_string(appended.size()) + "\"/>\n";
    appended += options.data == Data::AppendedRaw ? head + body : encoded;
    return element;
  };
  if (options.fieldData)
    out += "    <FieldData>\n" + dataArray(" Name=\"TimeValue\" NumberOfTuples=\"1\"", ValueType::Float64, 1, {0.5}) +
           "    </FieldData>\n";
  const std::size_t n = xyz.size() / 3;
  for (int p = 0; p < options.pieces; ++p) {
    const std::size_t begin = n * std::size_t(p) / std::size_t(options.pieces);
    const std::size_t end = n * std::size_t(p + 1) / std::size_t(options.pieces);
    const std::size_t count = end - begin;
    out += "    <Piece NumberOfPoints=\"" + std::to_string(count) + "\" " +
           (options.polyData ? "NumberOfVerts" : "NumberOfCells") + "=\"" + std::to_string(options.cells ? count : 0) +
           "\">\n      <PointData>\n";
    for (const auto& a : arrays) {
      std::vector<double> part(a.values.begin() + std::ptrdiff_t(begin * std::size_t(a.arity)),
                               a.values.begin() + std::ptrdiff_t(end * std::size_t(a.arity)));
      out += "        " + dataArray(" Name=\"" + a.name + "\"", a.type, a.arity, part);
    }
    out += "      </PointData>\n";
    if (options.cells) {
      std::vector<double> ids;
      for (std::size_t i = 0; i < count; ++i) ids.push_back(double(i));
      out += "      <CellData>\n        " + dataArray(" Name=\"cell_id\"", ValueType::Int32, 1, ids) +
             "      </CellData>\n";
    }
    std::vector<double> points(xyz.begin() + std::ptrdiff_t(3 * begin), xyz.begin() + std::ptrdiff_t(3 * end));
    out +=
        "      <Points>\n        " + dataArray(" Name=\"Points\"", options.pointType, 3, points) + "      </Points>\n";
    if (options.cells) {
      std::vector<double> connectivity, offsets, types;
      for (std::size_t i = 0; i < count; ++i) {
        connectivity.push_back(double(i));
        offsets.push_back(double(i + 1));
        types.push_back(1);
      }
      const std::string section = options.polyData ? "Verts" : "Cells";
      out += "      <" + section + ">\n        " +
             dataArray(" Name=\"connectivity\"", ValueType::Int64, 1, connectivity) + "        " +
             dataArray(" Name=\"offsets\"", ValueType::Int64, 1, offsets);
      if (!options.polyData) out += "        " + dataArray(" Name=\"types\"", ValueType::UInt8, 1, types);
      out += "      </" + section + ">\n";
    }
    out += "    </Piece>\n";
  }
  out += "  </" + type + ">\n";
  if (options.data == Data::AppendedRaw || options.data == Data::AppendedBase64)
    out += std::string("  <AppendedData encoding=\"") + (options.data == Data::AppendedRaw ? "raw" : "base64") +
           "\">\n   _" + appended + "\n  </AppendedData>\n";
  out += "</VTKFile>\n";
  return out;
}

// ---- Test data ----

/// `count` positions in [-50, 50)^3 that float32 holds exactly, seeded.
inline std::vector<double> vtkTestPositions(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-50.f, 50.f);
  std::vector<double> xyz(3 * count);
  for (double& v : xyz) v = position(rng);
  return xyz;
}

/// Values of `type` (exact in it and in float, so reads compare exactly), `count` × `arity`.
inline VtkTestArray vtkTestArray(std::string name, ValueType type, int arity, std::size_t count, unsigned seed,
                                 VtkTestArray::Kind kind = VtkTestArray::Kind::Field) {
  std::mt19937 rng(seed);
  VtkTestArray a{std::move(name), type, arity, {}, kind, {}};
  for (std::size_t i = 0; i < count * std::size_t(arity); ++i) {
    switch (type) {
      case ValueType::Int8:
        a.values.push_back(double(int(rng() % 256) - 128));
        break;
      case ValueType::UInt8:
        a.values.push_back(double(rng() % 256));
        break;
      case ValueType::Int16:
        a.values.push_back(double(int(rng() % 65536) - 32768));
        break;
      case ValueType::UInt16:
        a.values.push_back(double(rng() % 65536));
        break;
      case ValueType::Int32:
      case ValueType::Int64:
        a.values.push_back(double(std::int32_t(rng() % (1u << 24)) - (1 << 23)));
        break;
      case ValueType::UInt32:
      case ValueType::UInt64:
        a.values.push_back(double(rng() % (1u << 24)));
        break;
      default:
        a.values.push_back(double(float(std::int32_t(rng() % 2000001) - 1000000) / 1024.f));
        break;
    }
  }
  return a;
}

}  // namespace flipscope::testing
