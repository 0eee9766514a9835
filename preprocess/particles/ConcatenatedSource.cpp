// concatSources: several sources read one after another as one (the FLIP and the spray file of
// one frame).
#include <algorithm>

#include "core/Error.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope {
namespace {

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
  std::string format() const override {
    std::string formats;
    for (const auto& part : mParts) {
      std::string f = part->format();
      if (formats.find(f) == std::string::npos) formats += (formats.empty() ? "" : " + ") + f;
    }
    return formats;
  }
  /// The attributes every part holds (a chunk's columns then mean the same in every part).
  std::vector<AttributeDesc> attributes() const override {
    if (mParts.empty()) return {};
    std::vector<AttributeDesc> common = mParts.front()->attributes();
    for (const auto& part : mParts) {
      auto theirs = part->attributes();
      std::erase_if(common, [&](const AttributeDesc& a) { return std::find(theirs.begin(), theirs.end(), a) == theirs.end(); });
    }
    return common;
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

std::unique_ptr<ParticleSource> concatSources(std::vector<std::unique_ptr<ParticleSource>> parts) {
  return std::make_unique<ConcatenatedSource>(std::move(parts));
}

}  // namespace flipscope
