#include "preprocess/store/StoreInspection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <mutex>

#include "core/Error.h"

namespace flipscope {

FrameSummary summarizeFrame(const FrameIndex& frame, const StoreHeader& header) {
  FrameSummary s;
  s.frame = frame.frame;
  s.particles = frame.stats.particles;
  s.skippedInvalid = frame.stats.skippedInvalid;
  s.skippedOutside = frame.stats.skippedOutside;
  s.bricks = std::uint32_t(frame.bricks.size());
  for (const auto& b : frame.bricks) s.occupiedCells += b.cells;
  const double cells = double(s.bricks) * header.cellsPerBrick();
  s.fillRate = cells > 0 ? double(s.occupiedCells) / cells : 0;
  s.bitsPerParticle = s.particles ? cells / double(s.particles) : 0;
  s.storeBytes = frame.fileBytes;
  s.ratioToRaw = s.storeBytes ? 12.0 * double(s.particles) / double(s.storeBytes) : 0;
  s.attributeMin = frame.stats.attributeMin;
  s.attributeMax = frame.stats.attributeMax;
  s.kindCells = frame.stats.kindCells;
  return s;
}

double spacingInCells(const StoreHeader& header) {
  return header.particleSpacing > 0 && header.cellSize > 0 ? header.particleSpacing / header.cellSize : 0;
}

std::string incompleteStoreReason() {
  return "incomplete store: no frames yet (a convert is adding them, or one was interrupted or failed: then convert "
         "again)";
}

std::vector<std::string> checkFrameTable(const BrickStore& store) {
  std::vector<std::string> problems;
  if (store.incomplete())
    problems.push_back((store.directory() / kStoreHeaderName).string() + ": " + incompleteStoreReason());
  for (int f : store.missingFrames())
    problems.push_back(store.framePath(f).string() + ": " + store.missingFrameReason(f));
  return problems;
}

std::vector<std::string> verifyFrame(const BrickStore& store, const FrameIndex& frame) {
  std::vector<std::string> errors;
  std::mutex mutex;
  std::array<std::uint64_t, kParticleKindCount> kindCells{};
  bool decoded = true;  // every brick: only then are the kind counts complete
  tbb::parallel_for(std::size_t(0), frame.bricks.size(), [&](std::size_t i) {
    try {
      const DecodedBrick brick = store.readBrick(frame, std::uint32_t(i));
      std::array<std::uint64_t, kParticleKindCount> cells{};
      for (ParticleKind kind : brick.kinds) ++cells[std::size_t(kind)];
      std::lock_guard lock(mutex);
      for (std::size_t k = 0; k < kParticleKindCount; ++k) kindCells[k] += cells[k];
    } catch (const FileError& e) {
      std::lock_guard lock(mutex);
      errors.push_back(e.what());
      decoded = false;
    }
  });
  std::sort(errors.begin(), errors.end());
  for (std::size_t k = 0; decoded && k < kParticleKindCount; ++k)
    if (kindCells[k] != frame.stats.kindCells[k])
      errors.push_back(frame.file.string() + ": the bricks hold " + std::to_string(kindCells[k]) + " " +
                       particleKindName(ParticleKind(k)) + " cells, the footer says " +
                       std::to_string(frame.stats.kindCells[k]));
  return errors;
}

}  // namespace flipscope
