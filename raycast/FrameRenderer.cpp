#include "raycast/FrameRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <unordered_map>

#include <glm/trigonometric.hpp>
#include <glm/vector_relational.hpp>

#include "core/Error.h"
#include "streaming/BrickMipmap.h"

namespace flipscope {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
}  // namespace

std::uint32_t sphereReach(float radius, float jitter) {
  return std::uint32_t(std::ceil(double(radius) + double(jitter) + 0.5) - 1.0);
}

std::uint32_t storedOverlap(const RenderSettings& settings) {
  const std::uint32_t reach = sphereReach(settings.radius, settings.jitter);
  if (settings.foam.mode == FoamMode::Keep) return reach;
  std::uint32_t overlap = reach + std::uint32_t(std::floor(settings.radius));
  // The volume's trilinear density at points of the brick reads 4^3 blocks from stored cell
  // 4 * floor(n / 4 - 1/2) on: n >= 6 keeps them clear of the outermost cells.
  if (settings.foam.mode == FoamMode::Volume) overlap = std::max(overlap, 6u);
  return std::min(overlap, kMaxOverlap);
}

float defaultSphereRadius(const StoreHeader& header, float jitter) {
  if (!(header.particleSpacing > 0) || !(header.cellSize > 0)) return 1.0f;
  float radius = std::max(1.0f, float(kDefaultRadiusPerSpacing * header.particleSpacing / header.cellSize));
  // The largest radius whose reach fits the border: reach = ceil(radius + jitter + 0.5) - 1.
  const float largest = float(kMaxOverlap) + 0.5f - jitter;
  return std::min(radius, std::max(largest, 0.5f));
}

void validate(const RenderSettings& s) {
  if (s.width == 0 || s.height == 0 || s.width > 16384 || s.height > 16384)
    throw InputError("--size: width and height must be in 1..16384, got " + std::to_string(s.width) + "x" +
                     std::to_string(s.height));
  if (!(s.radius > 0.0f) || !std::isfinite(s.radius))
    throw InputError("--radius: must be a positive number of cells, got " + std::to_string(s.radius));
  if (!(s.jitter >= 0.0f) || !std::isfinite(s.jitter))
    throw InputError("--jitter: must be 0 or a positive number of cells, got " + std::to_string(s.jitter));
  if (sphereReach(s.radius, s.jitter) > kMaxOverlap)
    throw InputError("--radius plus jitter reach " + std::to_string(sphereReach(s.radius, s.jitter)) +
                     " cells; at most " + std::to_string(kMaxOverlap) + " fit the bit-brick border");
  if (s.maxPasses < 1) throw InputError("--max-passes: must be at least 1");
  validate(s.foam);
  if (!(s.thicknessSaturationCells >= 0.0f) || !std::isfinite(s.thicknessSaturationCells))
    throw InputError("thickness saturation must be 0 or a positive number of cells");
}

namespace {
StreamerOptions streamerOptions(const StoreHeader& header, const RenderSettings& settings, std::uint32_t reach) {
  StreamerOptions options;
  options.conversion.brickSize = header.brickSize;
  options.conversion.overlap = storedOverlap(settings);
  options.conversion.attribute =
      header.attribute == AttributeKind::None ? AttributeReduction::None : AttributeReduction::Max;
  options.conversion.hideBubbles = header.particleKinds && settings.foam.hideBubbles;
  options.conversion.foamKinds = header.particleKinds && settings.foam.usesKinds();
  options.mipDilation = reach;
  options.threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  options.cacheBytes = settings.cpuCacheBytes;
  options.readAheadFrames = settings.readAheadFrames;
  return options;
}

/// The pool within the budget, shrunk until its largest buffer (the bits) fits the device.
PoolLayout poolLayout(const StoreHeader& header, const RenderSettings& settings, std::uint64_t maxBufferBytes) {
  validate(settings);
  const bool attributes = header.attribute != AttributeKind::None;
  const bool foam = settings.foam.mode != FoamMode::Keep;
  std::uint64_t budget = settings.gpuBudgetBytes;
  for (;;) {
    PoolLayout layout = PoolLayout::forBudget(header.brickSize, storedOverlap(settings), attributes, budget, foam);
    const std::uint64_t bits = std::uint64_t(layout.slots) * layout.subBricksPerSlot * 16;
    const std::uint64_t ring = layout.attributeCapacity * 2;
    if (bits <= maxBufferBytes && ring <= maxBufferBytes) return layout;
    budget = budget / 8 * 7;
  }
}
}  // namespace

namespace {
std::shared_ptr<BrickSource> checked(std::shared_ptr<BrickSource> source) {
  FLIPSCOPE_CHECK(source, "FrameRenderer without a brick source");
  return source;
}
}  // namespace

FrameRenderer::FrameRenderer(std::shared_ptr<BrickSource> source, std::unique_ptr<RaycastDevice> device,
                             const RenderSettings& settings)
    : mSource(checked(std::move(source))),
      mDevice(std::move(device)),
      mSettings(settings),
      mReach(sphereReach(settings.radius, settings.jitter)),
      mOverlap(storedOverlap(settings)),
      mPool(poolLayout(mSource->header(), settings, mDevice->maxBufferBytes())) {
  mDevice->allocatePool(mPool.layout());
  mStreamer = std::make_unique<Streamer>(mSource, streamerOptions(mSource->header(), settings, mReach));
}

FrameRenderer::~FrameRenderer() = default;

Box FrameRenderer::occupiedBounds(int first, int last) const { return flipscope::occupiedBounds(*mSource, first, last); }

RaycastParams FrameRenderer::params(const Camera& camera, const FrameIndex& frame) const {
  const StoreHeader& h = mSource->header();
  const PoolLayout& layout = mPool.layout();
  RaycastParams p{};
  const glm::dvec3 eye = (camera.eye - h.origin) / h.cellSize;
  p.eye = glm::vec4(glm::vec3(eye), 0.0f);
  p.forward = glm::vec4(glm::vec3(camera.forward()), float(std::tan(glm::radians(camera.fovYDegrees) * 0.5)));
  p.right = glm::vec4(glm::vec3(camera.right()), float(mSettings.width) / float(mSettings.height));
  p.up = glm::vec4(glm::vec3(camera.trueUp()), float(h.cellSize));
  p.image = glm::uvec4(mSettings.width, mSettings.height, std::uint32_t(frame.frame), 0);
  p.grid = glm::uvec4(h.brickGrid, h.brickSize);
  p.brick = glm::uvec4(mOverlap, mReach, frame.octree.levels, layout.subBricksPerSlot);
  p.pool = glm::uvec4(layout.mipWordsPerSlot, layout.attributes ? 1u : 0u, std::uint32_t(frame.bricks.size()),
                      layout.mipLevels);
  p.sphere = glm::vec4(mSettings.radius, mSettings.jitter, 0.0f, mSettings.thicknessSaturationCells);
  const FoamSettings& foam = mSettings.foam;
  p.foam = glm::uvec4(foam.mode == FoamMode::Keep     ? 0u
                      : foam.mode == FoamMode::Remove ? kFoamSkip
                                                      : kFoamSkip | kFoamVolume,
                      0u, 0u, 0u);
  p.volume = glm::vec4(foam.step, foam.extinction, foam.opacityStop, 0.0f);
  FLIPSCOPE_CHECK(layout.mipLevels <= kMaxMipLevels, "mip levels " << layout.mipLevels);
  for (std::uint32_t level = 1; level <= layout.mipLevels; ++level)
    p.mipLevels[level - 1] = glm::uvec4(bitBrickMipDims(level, h.brickSize, mOverlap),
                                        bitBrickMipWordOffset(level, h.brickSize, mOverlap));
  return p;
}

FoamClassifyParams FrameRenderer::foamParams(std::size_t slots) const {
  const PoolLayout& layout = mPool.layout();
  FoamClassifyParams p{};
  p.brick = glm::uvec4(layout.brickSize, mOverlap, layout.subBricksPerSlot,
                       std::uint32_t(slots * layout.subBricksPerSlot));
  p.sphere = glm::vec4(mSettings.radius, mSettings.foam.threshold, mSettings.foam.classifies() ? 1.0f : 0.0f, 0.0f);
  return p;
}

std::vector<std::uint32_t> FrameRenderer::pageTable(const FrameIndex& frame) const {
  std::vector<std::uint32_t> table(frame.bricks.size(), kNotResident);
  mPool.forEachResident(frame.frame, [&](glm::uvec3 coord, std::uint32_t slot) {
    const std::int64_t index = frame.octree.find(coord);
    FLIPSCOPE_CHECK(index >= 0, "a resident brick is not in its frame");
    table[std::size_t(index)] = slot;
  });
  return table;
}

RenderResult FrameRenderer::render(int frame, const Camera& camera, int direction) {
  RenderResult result;
  result.frame = frame;
  result.width = mSettings.width;
  result.height = mSettings.height;
  result.stats = trace(frame, camera, direction);
  const auto start = Clock::now();
  result.hits = mDevice->readHits();
  result.stats.totalMs += msSince(start);
  return result;
}

RenderStats FrameRenderer::trace(int frame, const Camera& camera, int direction) {
  const auto start = Clock::now();
  validate(camera, "camera");
  if (!mSource->hasFrame(frame)) throw InputError(mSource->name() + ": no frame " + std::to_string(frame));
  const auto index = mSource->frame(frame);
  const StoreHeader& header = mSource->header();

  RenderStats stats;
  stats.frameBricks = index->bricks.size();
  stats.poolBytes = mPool.layout().bytes();

  const glm::dvec3 eyeInBricks = (camera.eye - header.origin) / (header.cellSize * header.brickSize);
  mStreamer->setFrame(frame, direction);
  mStreamer->setEye(eyeInBricks);
  std::vector<std::uint32_t> pages = pageTable(*index);
  mDevice->setOctree(index->octree.nodes);
  mDevice->setPageTable(pages);
  mDevice->beginImage(mSettings.width, mSettings.height);
  RaycastParams params = this->params(camera, *index);

  std::vector<BrickKey> evicted;
  for (stats.passes = 1;; ++stats.passes) {
    const std::vector<std::uint32_t> requests = mDevice->trace(params);
    stats.traceMs += mDevice->lastTraceMs();
    if (requests.empty()) {
      stats.converged = true;
      break;
    }
    if (stats.passes == mSettings.maxPasses) break;
    stats.bricksRequested += requests.size();

    // Convert (or fetch from the CPU cache) every requested brick.
    auto streamStart = Clock::now();
    std::vector<glm::uvec3> coords;
    std::unordered_map<BrickKey, std::uint32_t, BrickKeyHash> wanted;  // key -> brick index
    for (std::uint32_t i : requests) {
      FLIPSCOPE_CHECK(i < index->bricks.size(), "request for brick " << i);
      coords.push_back(index->bricks[i].coord);
      wanted.emplace(BrickKey{frame, index->bricks[i].coord}, i);
    }
    const std::uint64_t failedBefore = mStreamer->stats().failed;
    mStreamer->request(coords);
    std::vector<std::shared_ptr<const ConvertedBrick>> bricks;
    while (bricks.size() < wanted.size()) {
      mStreamer->waitIdle();
      auto ready = mStreamer->takeReady(wanted.size());
      if (mStreamer->stats().failed > failedBefore) mStreamer->rethrowLastError();
      if (ready.empty())
        throw LogicError("the streamer delivered " + std::to_string(bricks.size()) + " of " +
                         std::to_string(wanted.size()) + " requested bricks");
      for (auto& brick : ready)
        if (wanted.contains(brick->key)) bricks.push_back(std::move(brick));
    }
    stats.streamMs += msSince(streamStart);

    // Upload nearest first: when the pool is too small for all, the front of the image goes first.
    auto uploadStart = Clock::now();
    auto distance = [&](const ConvertedBrick& b) {
      const glm::dvec3 d = glm::dvec3(b.key.coord) + 0.5 - eyeInBricks;
      return glm::dot(d, d);
    };
    std::sort(bricks.begin(), bricks.end(), [&](const auto& a, const auto& b) {
      const double da = distance(*a), db = distance(*b);
      return da != db ? da < db : wanted.at(a->key) < wanted.at(b->key);
    });
    const std::uint64_t batch = ++mBatch;
    std::vector<std::uint32_t> uploadedSlots;
    for (const auto& brick : bricks) {
      evicted.clear();
      const auto placement = mPool.place(brick->key, brick->bits.attributes.size(), batch, evicted);
      for (const BrickKey& key : evicted) {
        ++stats.bricksEvicted;
        if (key.frame != frame) continue;
        pages[std::size_t(index->octree.find(key.coord))] = kNotResident;
        // The pool cannot hold what this frame needs at once: thickness behind a hit becomes
        // best effort, so the bricks of hits and of thickness marches cannot evict each other
        // forever. Hits stay exact.
        params.sphere.z = 1.0f;
      }
      if (!placement) break;  // the pool holds this pass's bricks only: the rest next pass
      mDevice->uploadBrick(placement->slot, placement->attributeOffset, *brick);
      pages[wanted.at(brick->key)] = placement->slot;
      uploadedSlots.push_back(placement->slot);
      ++stats.bricksUploaded;
    }
    mDevice->setPageTable(pages);
    stats.uploadMs += msSince(uploadStart);
    // §3.5: the bricks uploaded in this pass are classified in one batch before the next trace.
    if (mSettings.foam.mode != FoamMode::Keep && !uploadedSlots.empty()) {
      mDevice->classifyFoam(uploadedSlots, foamParams(uploadedSlots.size()));
      stats.foamMs += mDevice->lastClassifyMs();
      stats.bricksClassified += uploadedSlots.size();
    }
  }
  stats.bricksResident = mPool.resident();
  stats.totalMs = msSince(start);
  return stats;
}

}  // namespace flipscope
