// openParticleFile / createParticleWriter: choose the format by the file extension;
// concatSources: several sources read one after another as one.
#include <algorithm>
#include <cctype>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope {
namespace {

enum class ParticleFormat { Raw, Ply, Vdb };

constexpr const char* kSupportedExtensions = ".vdb, .ply, .bin, .raw";

ParticleFormat formatOf(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".bin" || ext == ".raw") return ParticleFormat::Raw;
  if (ext == ".ply") return ParticleFormat::Ply;
  if (ext == ".vdb") return ParticleFormat::Vdb;
  throw FileError(path, "unknown particle file extension '" + path.extension().string() +
                            "' (supported: " + kSupportedExtensions + ")");
}

class ConcatenatedSource final : public ParticleSource {
 public:
  explicit ConcatenatedSource(std::vector<std::unique_ptr<ParticleSource>> parts) : mParts(std::move(parts)) {
    for (const auto& part : mParts) FLIPSCOPE_CHECK(part, "null source");
  }
  std::string name() const override {
    std::string names;
    for (const auto& part : mParts) names += (names.empty() ? "" : " + ") + part->name();
    return names;
  }
  bool hasVelocity() const override {
    return !mParts.empty() && std::all_of(mParts.begin(), mParts.end(), [](auto& p) { return p->hasVelocity(); });
  }
  std::optional<std::uint64_t> countHint() const override {
    std::uint64_t total = 0;
    for (const auto& part : mParts) {
      auto count = part->countHint();
      if (!count) return std::nullopt;
      total += *count;
    }
    return total;
  }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    bool velocity = hasVelocity();
    for (; mCurrent < mParts.size(); ++mCurrent) {
      if (mParts[mCurrent]->read(chunk, maxParticles)) {
        if (!velocity) chunk.velocities.clear();
        return true;
      }
    }
    chunk.clear();
    return false;
  }
  void rewind() override {
    for (auto& part : mParts) part->rewind();
    mCurrent = 0;
  }
  /// Only when every part has a hint: the parts' volumes and points add up.
  std::optional<SpacingHint> spacingHint() const override {
    SpacingHint total;
    for (const auto& part : mParts) {
      auto hint = part->spacingHint();
      if (!hint) return std::nullopt;
      total.volume += hint->volume;
      total.points += hint->points;
      total.origin += (total.origin.empty() ? "" : " + ") + hint->origin;
    }
    if (mParts.empty()) return std::nullopt;
    return total;
  }

 private:
  std::vector<std::unique_ptr<ParticleSource>> mParts;
  std::size_t mCurrent = 0;
};

}  // namespace

std::unique_ptr<ParticleSource> openParticleFile(const std::filesystem::path& path, const ReadOptions& options) {
  ParticleFormat format = formatOf(path);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw FileError(path, "no such file");
  switch (format) {
    case ParticleFormat::Raw:
      return detail::openRawParticles(InputFile(path));
    case ParticleFormat::Ply:
      return detail::openPlyParticles(InputFile(path), options);
    case ParticleFormat::Vdb:
      return detail::openVdbPoints(path, options);
  }
  FLIPSCOPE_CHECK(false, "format=" << int(format));
}

std::unique_ptr<ParticleSource> detail::openParticleBytes(const std::filesystem::path& name,
                                                          std::span<const std::byte> bytes,
                                                          const ReadOptions& options) {
  switch (formatOf(name)) {
    case ParticleFormat::Raw:
      return openRawParticles(InputFile(name, bytes));
    case ParticleFormat::Ply:
      return openPlyParticles(InputFile(name, bytes), options);
    case ParticleFormat::Vdb:
      return openVdbPointsBytes(name, bytes, options);
  }
  FLIPSCOPE_CHECK(false, "unknown format");
}

std::unique_ptr<ParticleSource> concatSources(std::vector<std::unique_ptr<ParticleSource>> parts) {
  return std::make_unique<ConcatenatedSource>(std::move(parts));
}

std::unique_ptr<ParticleWriter> createParticleWriter(const std::filesystem::path& path, const WriteOptions& options) {
  switch (formatOf(path)) {
    case ParticleFormat::Raw:
      return detail::createRawWriter(path);
    case ParticleFormat::Ply:
      return detail::createPlyWriter(path, options);
    case ParticleFormat::Vdb:
      return detail::createVdbWriter(path, options);
  }
  FLIPSCOPE_CHECK(false, "unknown format");
}

}  // namespace flipscope
