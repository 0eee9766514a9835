// Houdini's modern geometry files as particles: the binary JSON .bgeo (Houdini 12 and later)
// and its ASCII twin .geo, through one walker (GeoScan.h) over either token stream
// (JsonReader.h). The points are the particles: P (its first 3 components; float or double),
// v as the velocity, and every other numeric point attribute as a column. Topology,
// primitives, vertices and groups are skipped; a file whose points are only the anchors of
// volumes, packed or quadric primitives (or that has no points) is refused, saying what it
// holds. Memory: the layout from the scan and one read buffer (and page) a selected attribute,
// whatever the file size, in either encoding: ASCII files are read through seeks to where each
// attribute's values start, like binary ones, so no decoded attribute is held. .bgeo.sc
// reaches this reader decoded by ScfContainer.cpp.
#include <algorithm>
#include <cstring>
#include <optional>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/houdini/AttributeCursor.h"
#include "preprocess/particles/houdini/GeoScan.h"
#include "preprocess/particles/houdini/JsonReader.h"

namespace flipscope::detail {
namespace houdini {
namespace {

enum class PrimitiveKind { Volume, Packed, Quadric, Other };

/// What a primitive type's points are: anchors (volumes, packed and quadric primitives have one
/// point, their position) or the geometry itself (polygons, curves, particle systems, ...).
PrimitiveKind primitiveKind(const std::string& type) {
  if (type == "Volume" || type == "VDB") return PrimitiveKind::Volume;
  if (type.rfind("Packed", 0) == 0 || type == "AlembicRef" || type == "Agent") return PrimitiveKind::Packed;
  if (type == "Sphere" || type == "Tube" || type == "Circle" || type == "MetaBall" || type == "MetaSQuad")
    return PrimitiveKind::Quadric;
  return PrimitiveKind::Other;
}

std::string plural(std::uint64_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// "7 volumes (Volume)", "3 primitives (PackedGeometry, Sphere)".
std::string describePrimitives(const GeoLayout& layout) {
  std::string types;
  bool sameKind = true;
  for (const auto& [type, entries] : layout.primitiveTypes) {
    types += (types.empty() ? "" : ", ") + type;
    sameKind = sameKind && primitiveKind(type) == primitiveKind(layout.primitiveTypes.front().first);
  }
  const std::uint64_t n = layout.primitiveCount;
  std::string what = plural(n, "primitive", "primitives");
  if (sameKind && !layout.primitiveTypes.empty()) {
    switch (primitiveKind(layout.primitiveTypes.front().first)) {
      case PrimitiveKind::Volume: what = plural(n, "volume", "volumes"); break;
      case PrimitiveKind::Packed: what = plural(n, "packed primitive", "packed primitives"); break;
      case PrimitiveKind::Quadric: what = plural(n, "quadric primitive", "quadric primitives"); break;
      case PrimitiveKind::Other: break;
    }
  }
  return types.empty() ? what : what + " (" + types + ")";
}

class HoudiniJsonReader final : public ParticleSource {
 public:
  HoudiniJsonReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    const std::vector<std::byte> head = mFile.peekHead(1);
    mEncoding = !head.empty() && head[0] == std::byte{0x7f} ? JsonEncoding::Binary : JsonEncoding::Ascii;
    mLayout = scanGeometry(mFile, mEncoding);
    const std::filesystem::path& path = mFile.path();
    if (mLayout.pointCount == 0)
      throw FileError(path, mLayout.primitiveCount == 0 && mLayout.primitiveTypes.empty()
                                ? std::string("holds no points (an empty geometry)")
                                : "holds no points, only " + describePrimitives(mLayout));
    const bool anchorsOnly =
        !mLayout.primitiveTypes.empty() &&
        std::all_of(mLayout.primitiveTypes.begin(), mLayout.primitiveTypes.end(),
                    [](const auto& entry) { return primitiveKind(entry.first) != PrimitiveKind::Other; });
    if (anchorsOnly)
      throw FileError(path, "holds no point cloud: only " + describePrimitives(mLayout) + ", whose positions are its " +
                                plural(mLayout.pointCount, "point", "points"));
    const PointAttribute* position = nullptr;
    const PointAttribute* velocity = nullptr;
    for (const auto& attribute : mLayout.pointAttributes) {
      if (attribute.name == "P") {
        position = &attribute;
        continue;
      }
      if (attribute.name == "v" && attribute.arity == 3) velocity = &attribute;
      mAttributes.push_back({attribute.name, attribute.type, attribute.arity});
      mAttributeLayouts.push_back(&attribute);
    }
    if (!position) throw FileError(path, "has no numeric point attribute 'P' (the positions)");
    if (position->arity < 3)
      throw FileError(path, "point attribute 'P' has " + std::to_string(position->arity) +
                                " components, expected 3 (or 4)");
    mPositionArity = std::size_t(position->arity);
    mPosition.emplace(mFile, mEncoding, *position, mLayout.pointCount);
    if (options.velocity && velocity) mVelocity.emplace(mFile, mEncoding, *velocity, mLayout.pointCount);
    mSelected = selectAttributes(mAttributes, options, path);
    for (std::size_t index : mSelected)
      mColumns.emplace_back(mFile, mEncoding, *mAttributeLayouts[index], mLayout.pointCount);
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    return std::string(mEncoding == JsonEncoding::Binary ? "Houdini binary JSON geometry (.bgeo)"
                                                         : "Houdini ASCII JSON geometry (.geo)") +
           ", Houdini " + (mLayout.fileVersion.empty() ? std::string("(no fileversion)") : mLayout.fileVersion);
  }
  /// Houdini's world is +y up.
  UpAxis upAxis() const override { return UpAxis::Y; }
  std::vector<AttributeDesc> attributes() const override { return mAttributes; }
  bool hasVelocity() const override { return mVelocity.has_value(); }
  std::optional<std::uint64_t> countHint() const override { return mLayout.pointCount; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    const auto n = std::size_t(std::min<std::uint64_t>(maxParticles, mLayout.pointCount - mNext));
    if (chunk.attributes.size() != mSelected.size()) chunk.attributes = makeColumns(mAttributes, mSelected);
    if (n == 0) return false;
    chunk.positions.resize(n);
    if (mPositionArity == 3) {
      mPosition->read(reinterpret_cast<float*>(chunk.positions.data()), n);
    } else {
      mScratch.resize(n * mPositionArity);
      mPosition->read(mScratch.data(), n);
      for (std::size_t i = 0; i < n; ++i) std::memcpy(&chunk.positions[i], mScratch.data() + i * mPositionArity, 12);
    }
    if (mVelocity) {
      chunk.velocities.resize(n);
      mVelocity->read(reinterpret_cast<float*>(chunk.velocities.data()), n);
    }
    for (std::size_t c = 0; c < mSelected.size(); ++c) {
      AttributeColumn& column = chunk.attributes[c];
      const AttributeDesc& desc = mAttributes[mSelected[c]];
      if (column.name != desc.name || column.arity != desc.arity) column = {desc.name, desc.arity, {}};
      column.values.resize(n * std::size_t(desc.arity));
      mColumns[c].read(column.values.data(), n);
    }
    mNext += n;
    return true;
  }

  void rewind() override {
    mNext = 0;
    mPosition->rewind();
    if (mVelocity) mVelocity->rewind();
    for (auto& column : mColumns) column.rewind();
  }

 private:
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "positions are read as packed floats");

  InputFile mFile;
  JsonEncoding mEncoding = JsonEncoding::Binary;
  GeoLayout mLayout;
  std::vector<AttributeDesc> mAttributes;
  std::vector<const PointAttribute*> mAttributeLayouts;  ///< of mAttributes
  std::size_t mPositionArity = 3;
  std::optional<AttributeCursor> mPosition, mVelocity;
  std::vector<std::size_t> mSelected;
  std::vector<AttributeCursor> mColumns;  ///< of mSelected
  std::uint64_t mNext = 0;
  std::vector<float> mScratch;
};

}  // namespace
}  // namespace houdini

bool isHoudiniJson(std::span<const std::byte> head) {
  using houdini::kBinaryMagic;
  using houdini::kSwappedMagic;
  if (head.size() >= 5 &&
      (std::memcmp(head.data(), kBinaryMagic, 5) == 0 || std::memcmp(head.data(), kSwappedMagic, 5) == 0))
    return true;
  // ASCII: '[' then "fileversion", the first key Houdini writes, after optional white space.
  std::size_t i = 0;
  auto skipSpace = [&]() {
    while (i < head.size() && (head[i] == std::byte{' '} || head[i] == std::byte{'\t'} || head[i] == std::byte{'\n'} ||
                               head[i] == std::byte{'\r'}))
      ++i;
  };
  skipSpace();
  if (i >= head.size() || head[i] != std::byte{'['}) return false;
  ++i;
  skipSpace();
  constexpr std::string_view kKey = "\"fileversion\"";
  return head.size() - i >= kKey.size() && std::memcmp(head.data() + i, kKey.data(), kKey.size()) == 0;
}

std::unique_ptr<ParticleSource> openHoudiniJson(InputFile file, const ReadOptions& options) {
  return std::make_unique<houdini::HoudiniJsonReader>(std::move(file), options);
}

}  // namespace flipscope::detail
