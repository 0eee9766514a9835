#include "raycast/CpuRaycaster.h"

#include <chrono>
#include <memory>
#include <thread>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "raycast/CpuRaycastKernel.h"
#include "raycast/NearSphereMask.h"

namespace flipscope {

std::vector<std::uint32_t> attributeBases(const BitBrick& bits, std::uint64_t attributeOffset) {
  std::vector<std::uint32_t> bases(bits.subBricks.size(), 0);
  if (!bits.hasAttributes()) return bases;
  for (std::uint32_t i = 0; i < bases.size(); ++i) {
    const std::uint64_t base = attributeOffset + bits.attributeBase(i);
    FLIPSCOPE_CHECK(base <= 0xffffffffu, "attribute ring beyond 32-bit indices");
    bases[i] = std::uint32_t(base);
  }
  return bases;
}

std::string CpuRaycaster::name() const {
  return "CPU reference (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
}

void CpuRaycaster::allocatePool(const PoolLayout& layout) {
  mPool.layout = PoolLayout{};  // no slots until every array is made (RaycastDevice's contract)
  const auto fresh = [](auto& array, std::size_t size) {
    std::remove_cvref_t<decltype(array)>().swap(array);  // let the old one go first
    array.resize(size);
  };
  const std::size_t slots = layout.slots;
  fresh(mPool.subBricks, slots * layout.subBricksPerSlot);
  fresh(mPool.mipWords, slots * layout.mipWordsPerSlot);
  fresh(mPool.attributeBases, layout.attributes ? slots * layout.subBricksPerSlot : 0);
  fresh(mPool.attributes, layout.attributeCapacity);
  fresh(mPool.foamBits, layout.foam ? slots * layout.subBricksPerSlot : 0);
  fresh(mPool.foamOccupancy, layout.foam ? slots * layout.foamOccupancyWords() : 0);
  fresh(mPool.halfCounts, layout.marchTables ? slots * layout.subBricksPerSlot * 4 : 0);
  fresh(mPool.nearSpheres, layout.marchTables ? slots * nearSphereMaskWords(layout.brickSize) : 0);
  fresh(mPool.clearDistances, layout.marchTables ? slots * layout.subBricksPerSlot : 0);
  fresh(mPool.nearDistances, layout.marchTables ? slots * nearSphereGroupCount(layout.brickSize) : 0);
  fresh(mPool.setBounds, layout.marchTables ? slots : 0);
  mPool.layout = layout;
}

void CpuRaycaster::setOctree(std::span<const OctreeNode> nodes) {
  mPool.nodes.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) mPool.nodes[i] = {nodes[i].childMask, nodes[i].firstChild};
}

void CpuRaycaster::setPageTable(std::span<const std::uint32_t> pageTable) {
  mPool.pageTable.assign(pageTable.begin(), pageTable.end());
}

void CpuRaycaster::uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) {
  const PoolLayout& layout = mPool.layout;
  FLIPSCOPE_CHECK(slot < layout.slots && brick.bits.subBricks.size() == layout.subBricksPerSlot &&
                  brick.mipmap.size() == layout.mipWordsPerSlot);
  std::copy(brick.bits.subBricks.begin(), brick.bits.subBricks.end(),
            mPool.subBricks.begin() + std::size_t(slot) * layout.subBricksPerSlot);
  std::copy(brick.mipmap.begin(), brick.mipmap.end(),
            mPool.mipWords.begin() + std::size_t(slot) * layout.mipWordsPerSlot);
  if (layout.attributes) {
    const auto bases = attributeBases(brick.bits, attributeOffset);
    std::copy(bases.begin(), bases.end(), mPool.attributeBases.begin() + std::size_t(slot) * layout.subBricksPerSlot);
    FLIPSCOPE_CHECK(attributeOffset + brick.bits.attributes.size() <= mPool.attributes.size());
    std::copy(brick.bits.attributes.begin(), brick.bits.attributes.end(), mPool.attributes.begin() + attributeOffset);
  }
  if (layout.foam) {
    const auto foam = mPool.foamBits.begin() + std::size_t(slot) * layout.subBricksPerSlot;
    if (brick.foamKinds.empty()) {
      std::fill(foam, foam + layout.subBricksPerSlot, glm::uvec4(0));
    } else {
      FLIPSCOPE_CHECK(brick.foamKinds.size() == layout.subBricksPerSlot);
      std::copy(brick.foamKinds.begin(), brick.foamKinds.end(), foam);
    }
  }
}

void CpuRaycaster::uploadBricks(std::span<const BrickUpload> uploads) {
  tbb::parallel_for(std::size_t(0), uploads.size(), [&](std::size_t i) {
    uploadBrick(uploads[i].slot, uploads[i].attributeOffset, *uploads[i].brick);
  });
}

void CpuRaycaster::classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) {
  const PoolLayout& layout = mPool.layout;
  FLIPSCOPE_CHECK(layout.foam && params.subBricksPerSlot == layout.subBricksPerSlot &&
                  params.batchSubBricks == slots.size() * layout.subBricksPerSlot);
  // In place, as on the GPU: a sub-brick's classification reads no foam bits but its own.
  timedClassify(slots, params, [&](std::uint32_t slot) {
    glsl::FoamKernel kernel{params, &mPool};
    glm::uvec4* foam = &mPool.foamBits[std::size_t(slot) * layout.subBricksPerSlot];
    for (std::uint32_t s = 0; s < layout.subBricksPerSlot; ++s) foam[s] = kernel.fcClassify(slot, s);
  });
}

void CpuRaycaster::timedClassify(std::span<const std::uint32_t> slots, const FoamClassifyParams& params,
                                 const std::function<void(std::uint32_t slot)>& classify) {
  const PoolLayout& layout = mPool.layout;
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(std::size_t(0), slots.size(), [&](std::size_t i) {
    FLIPSCOPE_CHECK(slots[i] < layout.slots);
    classify(slots[i]);
    // The occupancy of a brick reads its foam once every sub-brick of it is classified.
    glsl::FoamKernel kernel{params, &mPool};
    std::uint32_t* occupancy = &mPool.foamOccupancy[std::size_t(slots[i]) * layout.foamOccupancyWords()];
    for (std::uint32_t w = 0; w < layout.foamOccupancyWords(); ++w) occupancy[w] = kernel.fcOccupancyWord(slots[i], w);
  });
  mLastClassifyMs = msSince(start);
}

std::vector<glm::uvec4> CpuRaycaster::readFoam(std::uint32_t slot) {
  const PoolLayout& layout = mPool.layout;
  FLIPSCOPE_CHECK(layout.foam && slot < layout.slots);
  const auto first = mPool.foamBits.begin() + std::size_t(slot) * layout.subBricksPerSlot;
  return {first, first + layout.subBricksPerSlot};
}

void CpuRaycaster::beginImage(std::uint32_t width, std::uint32_t height) {
  mWidth = width;
  mHeight = height;
  mHits.resize(std::size_t(width) * height);
  mRaysFresh = true;  // the first pass writes every ray (rayAt)
}

std::span<const RayHit> CpuRaycaster::hits() {
  if (mRaysFresh) std::fill(mHits.begin(), mHits.end(), RayHit{});
  mRaysFresh = false;
  return mHits;
}

std::vector<std::uint32_t> CpuRaycaster::timedPass(
    const RaycastParams& params, const std::function<void(const glsl::RaycastPoolAccess& access)>& pass) {
  FLIPSCOPE_CHECK(params.width == mWidth && params.height == mHeight);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t brickCount = mPool.pageTable.size();
  std::unique_ptr<std::atomic<std::uint8_t>[]> flags(
      new std::atomic<std::uint8_t>[std::max<std::size_t>(brickCount, 1)]);
  for (std::size_t i = 0; i < brickCount; ++i) flags[i].store(0, std::memory_order_relaxed);
  pass(glsl::RaycastPoolAccess{params, &mPool, flags.get()});
  mRaysFresh = false;
  std::vector<std::uint32_t> requests;
  for (std::size_t i = 0; i < brickCount; ++i)
    if (flags[i].load(std::memory_order_relaxed)) requests.push_back(std::uint32_t(i));
  mLastTraceMs = msSince(start);
  return requests;
}

std::vector<std::uint32_t> CpuRaycaster::trace(const RaycastParams& params) {
  return timedPass(params, [&](const glsl::RaycastPoolAccess& access) {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, mHeight), [&](const tbb::blocked_range<std::uint32_t>& rows) {
      glsl::RaycastKernel kernel{access};  // the shared functions are non-const members
      for (std::uint32_t y = rows.begin(); y != rows.end(); ++y) {
        for (std::uint32_t x = 0; x < mWidth; ++x) {
          const std::size_t i = std::size_t(y) * mWidth + x;
          RayHit ray = rayAt(i);
          if (!kernel.rcNeedsPass(ray)) continue;
          kernel.rcPass(glm::uvec2(x, y), ray);
          mHits[i] = ray;
        }
      }
    });
  });
}

}  // namespace flipscope
