// OpenVDB point files: every PointDataGrid of a file (or those named in ReadOptions::grids),
// read leaf by leaf with delayed loading, so a file larger than memory streams; a leaf's
// attributes are dropped once read (rewind() reloads the grids). World positions are
// transform.indexToWorld(voxel coordinate + P), P decoded by OpenVDB for any codec.
// Velocities: the `v` attribute, or Blender Mantaflow's `particles_velocity*`.
// The only translation unit of flipscope that includes OpenVDB headers.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <mutex>
#include <ostream>
#include <sstream>
#include <streambuf>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/ParticleFormats.h"

namespace flipscope::detail {
namespace {

using openvdb::points::PointDataGrid;
using PointLeaf = PointDataGrid::TreeType::LeafNodeType;

/// Initializes OpenVDB once (thread safe). Also registers the attribute type of Blender
/// Mantaflow's `U` attribute (int32 with the truncate codec), which stock OpenVDB does not:
/// without it, reading any grid of a Mantaflow file fails.
void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] {
    openvdb::initialize();
    using MantaflowInt = openvdb::points::TypedAttributeArray<std::int32_t, openvdb::points::TruncateCodec>;
    if (!MantaflowInt::isRegistered()) MantaflowInt::registerType();
  });
}

/// OpenVDB's message for a corrupted file may quote megabytes of garbage read as a name:
/// keep the start, printable characters only, runs of spaces collapsed.
std::string shortMessage(const char* text) {
  constexpr std::size_t kMaxLength = 200;
  std::string result;
  for (const char* c = text; *c && result.size() < kMaxLength; ++c) {
    char printable = std::isprint(static_cast<unsigned char>(*c)) ? *c : '?';
    if (printable == ' ' && !result.empty() && result.back() == ' ') continue;
    result.push_back(printable);
  }
  if (result.size() == kMaxLength) result += "...";
  return result;
}

/// Runs `work`, turning OpenVDB's (and the standard library's) exceptions into FileError.
template <class Work>
void rethrowAsFileError(const std::filesystem::path& path, Work&& work) {
  try {
    work();
  } catch (const InputError&) {
    throw;
  } catch (const LogicError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw FileError(path, "corrupted OpenVDB file (an allocation failed while reading it)");
  } catch (const std::exception& e) {
    throw FileError(path, "corrupted or truncated OpenVDB file: " + shortMessage(e.what()));
  }
}

constexpr std::size_t kNoAttribute = openvdb::points::AttributeSet::INVALID_POS;

/// The attribute carrying velocities: `v`, else Blender Mantaflow's `particles_velocity*`.
std::size_t velocityAttribute(const openvdb::points::AttributeSet::Descriptor& descriptor) {
  auto isVec3f = [&](std::size_t index) {
    return descriptor.valueType(index) == openvdb::typeNameAsString<openvdb::Vec3f>();
  };
  std::size_t v = descriptor.find("v");
  if (v != kNoAttribute && isVec3f(v)) return v;
  for (const auto& [name, index] : descriptor.map())
    if (name.rfind("particles_velocity", 0) == 0 && isVec3f(index)) return index;
  return kNoAttribute;
}

std::string originText(const PointLeaf& leaf) {
  std::ostringstream text;
  text << leaf.origin();
  return text.str();
}

struct PointGrid {
  PointDataGrid::Ptr grid;
  std::vector<PointLeaf*> leaves;
  bool hasVelocity = false;
};

class VdbPointsReader final : public ParticleSource {
 public:
  VdbPointsReader(std::filesystem::path path, ReadOptions options)
      : mPath(std::move(path)), mOptions(std::move(options)) {
    initializeOpenVdb();
    rethrowAsFileError(mPath, [&] {
      loadGrids();
      std::uint64_t count = 0;
      for (const auto& g : mGrids) {
        const std::uint64_t points = openvdb::points::pointCount(g.grid->tree());
        count += points;
        addSpacingHint(g, points);
      }
      mCount = count;
    });
    bool any = false;
    mHasVelocity = mOptions.velocity;
    for (const auto& g : mGrids)
      if (!g.leaves.empty()) {
        any = true;
        mHasVelocity = mHasVelocity && g.hasVelocity;
      }
    mHasVelocity = mHasVelocity && any;
  }

  std::string name() const override { return mPath.string(); }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mCount; }
  /// Particles per active voxel of the topology (no attribute is read): a FLIP solver's
  /// points grid has a voxel per simulation cell, and its particles fill the active ones.
  std::optional<SpacingHint> spacingHint() const override {
    if (mSpacing.points == 0 || !(mSpacing.volume > 0) || !std::isfinite(mSpacing.volume)) return std::nullopt;
    return mSpacing;
  }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    rethrowAsFileError(mPath, [&] { readInto(chunk, maxParticles); });
    return chunk.size() > 0;
  }

  void rewind() override {
    rethrowAsFileError(mPath, [&] { loadGrids(); });
    mGrid = mLeaf = 0;
    mVoxel = 0;
    mPoint = 0;
  }

 private:
  void loadGrids() {
    mGrids.clear();
    expectVdbMagic();
    openvdb::io::File file(mPath.string());
    file.setCopyMaxBytes(0);  // read in place: no copy of the file to a temporary
    file.open(/*delayLoad=*/true);
    auto metadata = file.readAllGridMetadata();
    std::string present;
    for (const auto& grid : *metadata)
      present += (present.empty() ? "'" : ", '") + grid->getName() + "' (" + grid->type() + ")";
    if (present.empty()) present = "none";
    std::vector<std::string> names;
    if (mOptions.grids.empty()) {
      for (const auto& grid : *metadata)
        if (grid->isType<PointDataGrid>()) names.push_back(grid->getName());
      if (names.empty()) throw FileError(mPath, "no PointDataGrid in the file (grids: " + present + ")");
    } else {
      for (const auto& name : mOptions.grids) {
        auto it = std::find_if(metadata->begin(), metadata->end(), [&](auto& g) { return g->getName() == name; });
        if (it == metadata->end()) throw FileError(mPath, "no grid named '" + name + "' (grids: " + present + ")");
        if (!(*it)->isType<PointDataGrid>())
          throw FileError(mPath, "grid '" + name + "' is a " + (*it)->type() + ", not a PointDataGrid");
        names.push_back(name);
      }
    }
    for (const auto& name : names) {
      PointGrid g;
      g.grid = openvdb::gridPtrCast<PointDataGrid>(file.readGrid(name));
      for (auto leaf = g.grid->tree().beginLeaf(); leaf; ++leaf) g.leaves.push_back(leaf.getLeaf());
      if (!g.leaves.empty())
        g.hasVelocity = velocityAttribute(g.leaves[0]->attributeSet().descriptor()) != kNoAttribute;
      mGrids.push_back(std::move(g));
    }
    file.close();
  }

  void addSpacingHint(const PointGrid& g, std::uint64_t points) {
    const std::uint64_t active = g.grid->tree().activeVoxelCount();
    if (points == 0 || active == 0) return;
    mSpacing.volume += double(active) * g.grid->transform().voxelVolume();
    mSpacing.points += points;
    std::ostringstream text;
    text << (mSpacing.origin.empty() ? "OpenVDB grid '" : ", grid '") << g.grid->getName() << "': " << points
         << " points in " << active << " active voxels of " << g.grid->transform().voxelSize()[0];
    mSpacing.origin += text.str();
  }

  /// Rejects files that are not OpenVDB before OpenVDB parses them.
  void expectVdbMagic() const {
    std::int64_t magic = 0;  // written as 64 bits
    std::ifstream in(mPath, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(&magic), sizeof magic) || magic != openvdb::OPENVDB_MAGIC)
      throw FileError(mPath, "bad magic: not an OpenVDB file");
  }

  void readInto(ParticleChunk& chunk, std::size_t maxParticles) {
    while (chunk.size() < maxParticles && mGrid < mGrids.size()) {
      PointGrid& g = mGrids[mGrid];
      if (mLeaf == g.leaves.size()) {
        ++mGrid;
        mLeaf = 0;
        continue;
      }
      PointLeaf& leaf = *g.leaves[mLeaf];
      if (readLeaf(g, leaf, chunk, maxParticles)) {
        // Done with this leaf: drop its attributes so memory stays bounded by the topology.
        leaf.replaceAttributeSet(new openvdb::points::AttributeSet, /*allowMismatchingDescriptors=*/true);
        ++mLeaf;
        mVoxel = 0;
        mPoint = 0;
      }
    }
  }

  /// Appends points of `leaf` from (mVoxel, mPoint) on; returns true when the leaf is finished.
  bool readLeaf(const PointGrid& g, const PointLeaf& leaf, ParticleChunk& chunk, std::size_t maxParticles) {
    const auto& descriptor = leaf.attributeSet().descriptor();
    std::size_t p = descriptor.find("P");
    if (p == kNoAttribute || descriptor.valueType(p) != openvdb::typeNameAsString<openvdb::Vec3f>())
      throw FileError(mPath, "grid '" + g.grid->getName() + "': leaf at " + originText(leaf) +
                                 " has no vec3s position attribute P");
    openvdb::points::AttributeHandle<openvdb::Vec3f> positions(leaf.constAttributeArray(p));
    std::optional<openvdb::points::AttributeHandle<openvdb::Vec3f>> velocities;
    if (mHasVelocity) {
      std::size_t v = velocityAttribute(descriptor);
      if (v == kNoAttribute)
        throw FileError(mPath, "grid '" + g.grid->getName() + "': leaf at " + originText(leaf) +
                                   " has no velocity attribute, unlike the first leaf");
      velocities.emplace(leaf.constAttributeArray(v));
    }
    const openvdb::Index count = leaf.pointCount();
    if (positions.size() != count || (velocities && velocities->size() != count))
      throw FileError(mPath, "grid '" + g.grid->getName() + "': leaf at " + originText(leaf) + " has " +
                                 std::to_string(positions.size()) + " positions but its voxels index " +
                                 std::to_string(count) + " points");
    const openvdb::math::Transform& transform = g.grid->transform();
    for (; mVoxel < PointLeaf::SIZE; ++mVoxel) {
      const openvdb::Index end = std::min(openvdb::Index(leaf.getValue(mVoxel)), count);
      if (mPoint >= end) continue;
      const openvdb::Vec3d voxel = leaf.offsetToGlobalCoord(mVoxel).asVec3d();
      for (; mPoint < end; ++mPoint) {
        if (chunk.size() == maxParticles) return false;
        openvdb::Vec3d world = transform.indexToWorld(voxel + openvdb::Vec3d(positions.get(mPoint)));
        chunk.positions.emplace_back(float(world.x()), float(world.y()), float(world.z()));
        if (velocities) {
          openvdb::Vec3f v = velocities->get(mPoint);
          chunk.velocities.emplace_back(v.x(), v.y(), v.z());
        }
      }
    }
    return true;
  }

  std::filesystem::path mPath;
  ReadOptions mOptions;
  std::vector<PointGrid> mGrids;
  std::uint64_t mCount = 0;
  SpacingHint mSpacing;
  bool mHasVelocity = false;
  std::size_t mGrid = 0;
  std::size_t mLeaf = 0;
  openvdb::Index mVoxel = 0;
  openvdb::Index mPoint = 0;
};

/// Unbuffered std::streambuf that appends to an AtomicFile (which buffers itself).
class AtomicFileStreamBuffer final : public std::streambuf {
 public:
  explicit AtomicFileStreamBuffer(AtomicFile& file) : mFile(file) {}

 protected:
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    mFile.write(data, static_cast<std::size_t>(count));
    return count;
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    char byte = traits_type::to_char_type(c);
    mFile.write(&byte, 1);
    return c;
  }

 private:
  AtomicFile& mFile;
};

/// Points a PointDataGrid can store: voxel coordinates must fit OpenVDB's 32-bit Coord.
constexpr double kMaxVoxelCoordinate = 1 << 30;
/// Average points per occupied voxel aimed at when the voxel size comes from the points.
constexpr std::uint32_t kPointsPerVoxel = 8;

class VdbPointsWriter final : public ParticleWriter {
 public:
  VdbPointsWriter(const std::filesystem::path& path, const WriteOptions& options) : mFile(path), mOptions(options) {
    initializeOpenVdb();
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mOptions.velocity || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const glm::vec3& p = chunk.positions[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(mFile.destination().string() +
                         ": OpenVDB points cannot store the non-finite position of particle " +
                         std::to_string(mPositions.size()));
      mPositions.emplace_back(p.x, p.y, p.z);
      if (mOptions.velocity) {
        const glm::vec3& v = chunk.velocities[k];
        mVelocities.emplace_back(v.x, v.y, v.z);
      }
    }
  }

  void commit() override {
    namespace points = openvdb::points;
    points::PointAttributeVector<openvdb::Vec3f> positions(mPositions);
    double voxelSize = mOptions.vdbVoxelSize;
    if (voxelSize <= 0) voxelSize = mPositions.empty() ? 1.0 : points::computeVoxelSize(positions, kPointsPerVoxel);
    if (!(voxelSize > 0) || !std::isfinite(voxelSize)) voxelSize = 1.0;
    for (const auto& p : mPositions)
      if (std::abs(p.x()) / voxelSize > kMaxVoxelCoordinate || std::abs(p.y()) / voxelSize > kMaxVoxelCoordinate ||
          std::abs(p.z()) / voxelSize > kMaxVoxelCoordinate)
        throw InputError(mFile.destination().string() + ": position " + p.str() +
                         " is too far from the origin for voxel size " + std::to_string(voxelSize));
    auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *transform);
    auto grid = points::createPointDataGrid<points::NullCodec, PointDataGrid>(*index, positions, *transform);
    if (mOptions.velocity) {
      points::appendAttribute<openvdb::Vec3f>(grid->tree(), "v");
      points::PointAttributeVector<openvdb::Vec3f> velocities(mVelocities);
      points::populateAttribute(grid->tree(), index->tree(), "v", velocities);
    }
    grid->setName("particles");
    AtomicFileStreamBuffer buffer(mFile);
    std::ostream stream(&buffer);
    stream.exceptions(std::ios::badbit | std::ios::failbit);
    openvdb::io::Stream(stream).write(openvdb::GridCPtrVec{grid});
    stream.flush();
    mFile.commit();
  }

 private:
  AtomicFile mFile;
  WriteOptions mOptions;
  std::vector<openvdb::Vec3f> mPositions;
  std::vector<openvdb::Vec3f> mVelocities;
};

}  // namespace

std::unique_ptr<ParticleSource> openVdbPoints(const std::filesystem::path& path, const ReadOptions& options) {
  return std::make_unique<VdbPointsReader>(path, options);
}

std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<VdbPointsWriter>(path, options);
}

}  // namespace flipscope::detail
