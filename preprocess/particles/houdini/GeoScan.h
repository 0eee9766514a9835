// The first pass over a Houdini JSON geometry (binary .bgeo or ASCII .geo, GA file format of
// the HDK): the header (fileversion, pointcount, vertexcount, primitivecount, info), the point
// attributes (name, storage, tuple size, how their values are stored and where they start in
// the file), and the primitive types. It walks the whole file, so that damage anywhere is found
// before any point is read, and checks every value count against the point count. Topology,
// vertex and primitive attributes, primitives and groups are skipped.
//
// Memory: the layout of each attribute (its constant-page flags: one bit a page) and the binary
// token definitions; the values stay in the file (AttributeCursor reads them).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/houdini/JsonReader.h"

namespace flipscope::detail::houdini {

/// How an attribute's values are stored (the keys of its "values" entry).
enum class ValueLayout : std::uint8_t {
  Paged,   ///< "rawpagedata": page after page, each page holding its packed subvectors in turn
  Tuples,  ///< "tuples": one array of `arity` numbers a point
  Arrays,  ///< "arrays": one array of `pointCount` numbers a component
};

struct PointAttribute {
  std::string name;
  std::string storage;  ///< as the file spells it: "fpreal32", "int32", ...
  ValueType type = ValueType::Float32;
  int arity = 1;
  ValueLayout layout = ValueLayout::Paged;
  std::uint64_t pageSize = 0;                    ///< Paged: points a page
  std::vector<int> packing;                      ///< Paged: subvector sizes, adding up to arity
  std::vector<std::vector<bool>> constantPages;  ///< Paged: a subvector's flags, one a page (or none)
  std::vector<std::uint64_t> dataOffsets;        ///< where the value arrays start (Arrays: one a component)
};

struct GeoLayout {
  JsonEncoding encoding = JsonEncoding::Binary;
  std::string fileVersion;  ///< "fileversion": the Houdini version that wrote the file
  std::uint64_t pointCount = 0, vertexCount = 0, primitiveCount = 0;
  std::vector<PointAttribute> pointAttributes;                 ///< the numeric ones, in file order
  std::vector<std::pair<std::string, std::uint64_t>> primitiveTypes;  ///< type ("run"s by their runtype), entries
};

/// Largest supported values: larger ones are refused as implausible.
inline constexpr std::uint64_t kMaxPoints = std::uint64_t(1) << 44;
inline constexpr int kMaxArity = 1024;
inline constexpr std::uint64_t kMaxPageSize = std::uint64_t(1) << 16;    ///< Houdini's pages hold 1024 points
inline constexpr std::uint64_t kMaxPageValues = std::uint64_t(1) << 22;  ///< pageSize * arity

/// Reads the layout of `file`, a binary JSON file (after its magic) or ASCII JSON text.
/// Throws FileError for malformed or truncated files.
GeoLayout scanGeometry(InputFile& file, JsonEncoding encoding);

/// Number of values the "rawpagedata" of `attribute` must hold for `points` points.
std::uint64_t pagedValueCount(const PointAttribute& attribute, std::uint64_t points);

}  // namespace flipscope::detail::houdini
