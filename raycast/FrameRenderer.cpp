#include "raycast/FrameRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <unordered_set>

#include <glm/trigonometric.hpp>
#include <glm/vector_relational.hpp>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/NumberText.h"
#include "raycast/FirstBricks.h"
#include "streaming/BrickMipmap.h"

namespace flipscope {

namespace {
using Clock = std::chrono::steady_clock;
/// Bricks advance() uploads (and classifies for foam) between two looks at its budget. The paper
/// classifies batches of 256 (§3.5); fewer keep a slice short on the CPU reference.
constexpr std::size_t kUploadBatch = 64;
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
    throw InputError("--radius: must be a positive number of cells, got " + numberText(s.radius));
  if (!(s.jitter >= 0.0f) || !std::isfinite(s.jitter))
    throw InputError("--jitter: must be 0 or a positive number of cells, got " + numberText(s.jitter));
  if (sphereReach(s.radius, s.jitter) > kMaxOverlap)
    throw InputError("--radius plus jitter reach " + numberText(sphereReach(s.radius, s.jitter)) + " cells; at most " +
                     std::to_string(kMaxOverlap) + " fit the bit-brick border");
  if (s.maxPasses < 1) throw InputError("--max-passes: must be at least 1");
  validate(s.foam);
  if (!(s.thicknessSaturationCells >= 0.0f) || !std::isfinite(s.thicknessSaturationCells))
    throw InputError("thickness saturation must be 0 or a positive number of cells");
}

namespace {
/// `attributes`: the source's bricks carry attribute values (BrickSource::carriesAttributes).
StreamerOptions streamerOptions(const StoreHeader& header, bool attributes, const RenderSettings& settings,
                                std::uint32_t reach) {
  StreamerOptions options;
  options.conversion.brickSize = header.brickSize;
  options.conversion.overlap = storedOverlap(settings);
  options.conversion.attribute = attributes ? AttributeReduction::Max : AttributeReduction::None;
  options.conversion.hideBubbles = header.particleKinds && settings.foam.hideBubbles;
  options.conversion.foamKinds = header.particleKinds && settings.foam.usesKinds();
  options.mipDilation = reach;
  options.threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  options.cacheBytes = settings.cpuCacheBytes;
  options.readAheadFrames = settings.readAheadFrames;
  return options;
}

/// The largest pool within the budget, shrunk until its largest buffer (the bits) fits the
/// device.
PoolLayout budgetPoolLayout(const StoreHeader& header, bool attributes, const RenderSettings& settings,
                            const RaycastDevice& device) {
  const std::uint64_t maxBufferBytes = device.maxBufferBytes();
  validate(settings);
  const bool foam = settings.foam.mode != FoamMode::Keep;
  std::uint64_t budget = settings.gpuBudgetBytes;
  for (;;) {
    PoolLayout layout = PoolLayout::forBudget(header.brickSize, storedOverlap(settings), attributes, budget, foam,
                                              device.keepsMarchTables(), sphereReach(settings.radius, settings.jitter));
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
      mBudgetPool(budgetPoolLayout(mSource->header(), mSource->carriesAttributes(), settings, *mDevice)),
      mPool(mBudgetPool.withSlots(0)) {
  mDevice->allocatePool(mPool.layout());
  mStreamer = std::make_unique<Streamer>(
      mSource, streamerOptions(mSource->header(), mSource->carriesAttributes(), settings, mReach));
}

FrameRenderer::~FrameRenderer() = default;

Box FrameRenderer::occupiedBounds(int first, int last) const { return flipscope::occupiedBounds(*mSource, first, last); }

RaycastParams FrameRenderer::params(const Camera& camera, const FrameIndex& frame) const {
  const StoreHeader& h = mSource->header();
  const PoolLayout& layout = mPool.layout();
  RaycastParams p{};
  const glm::dvec3 eye = (camera.eye - h.origin) / h.cellSize;
  p.eye = glm::vec4(glm::vec3(eye), 0.0f);
  p.forward = glm::vec4(glm::vec3(camera.forward()), 0.0f);
  p.right = glm::vec4(glm::vec3(camera.right()), 0.0f);
  p.up = glm::vec4(glm::vec3(camera.trueUp()), 0.0f);
  p.bricksPerAxis = glm::uvec4(h.brickGrid, 0u);
  p.tanHalfFovY = float(std::tan(glm::radians(camera.fovYDegrees) * 0.5));
  p.aspect = float(mSettings.width) / float(mSettings.height);
  p.cellSize = float(h.cellSize);
  p.width = mSettings.width;
  p.height = mSettings.height;
  p.timeStep = std::uint32_t(frame.frame);
  p.brickSize = h.brickSize;
  p.overlap = mOverlap;
  p.reach = mReach;
  p.octreeLevels = frame.octree.levels;
  p.subBricksPerSlot = layout.subBricksPerSlot;
  p.mipWordsPerSlot = layout.mipWordsPerSlot;
  p.attributes = layout.attributes ? 1u : 0u;
  p.frameBricks = std::uint32_t(frame.bricks.size());
  p.mipLevelCount = layout.mipLevels;
  p.radius = mSettings.radius;
  p.maxJitter = mSettings.jitter;
  p.thicknessBestEffort = 0u;
  p.thicknessSaturationCells = mSettings.thicknessSaturationCells;
  const FoamSettings& foam = mSettings.foam;
  p.foamFlags = foam.mode == FoamMode::Keep ? 0u : foam.mode == FoamMode::Remove ? kFoamSkip : kFoamSkip | kFoamVolume;
  p.foamStep = foam.step;
  p.foamExtinction = foam.extinction;
  p.foamOpacityStop = foam.opacityStop;
  FLIPSCOPE_CHECK(layout.mipLevels <= kMaxMipLevels, "mip levels " << layout.mipLevels);
  for (std::uint32_t level = 1; level <= layout.mipLevels; ++level)
    p.mipLevels[level - 1] = glm::uvec4(bitBrickMipDims(level, h.brickSize, mOverlap),
                                        bitBrickMipWordOffset(level, h.brickSize, mOverlap));
  return p;
}

FoamClassifyParams FrameRenderer::foamParams(std::size_t slots) const {
  const PoolLayout& layout = mPool.layout();
  FoamClassifyParams p{};
  p.brickSize = layout.brickSize;
  p.overlap = mOverlap;
  p.subBricksPerSlot = layout.subBricksPerSlot;
  p.batchSubBricks = std::uint32_t(slots * layout.subBricksPerSlot);
  p.radius = mSettings.radius;
  p.threshold = mSettings.foam.threshold;
  p.classify = mSettings.foam.classifies() ? 1u : 0u;
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

/// The frame begun by begin(): its index, pass parameters, page table and statistics so far.
struct FrameRenderer::ActiveFrame {
  int frame = 0;
  std::shared_ptr<const FrameIndex> index;
  RaycastParams params{};
  std::vector<std::uint32_t> pages;
  glm::dvec3 eyeInBricks{0};
  RenderStats stats;
  std::uint64_t failedBefore = 0;  ///< Streamer failures before this frame
  bool traceDue = true;            ///< a brick arrived since the last pass (or none ran yet)
  bool finished = false;
};

RenderStats FrameRenderer::trace(int frame, const Camera& camera, int direction) {
  const auto start = Clock::now();
  begin(frame, camera, direction);
  if (mSettings.prefetch) prefetch(camera);
  runPasses(true, std::numeric_limits<double>::infinity(), nullptr);
  mActive->stats.totalMs = msSince(start);
  return mActive->stats;
}

void FrameRenderer::prefetch(const Camera& camera) {
  ActiveFrame& a = *mActive;
  std::size_t frameResident = 0;
  for (std::uint32_t page : a.pages) frameResident += page != kNotResident;
  if (frameResident == a.pages.size()) return;  // warm: nothing to find
  // The first pass's bricks: the first along each ray.
  std::vector<glm::uvec3> first;
  const std::uint32_t stride = firstBrickStride(mSettings.width, mSettings.height);
  for (std::uint32_t i :
       firstBricksAlongRays(camera, mSettings.width, mSettings.height, stride, mSource->header(), a.index->octree))
    if (a.pages[i] == kNotResident) first.push_back(a.index->bricks[i].coord);
  if (first.empty()) return;
  // Those in view, where the pool holds the whole frame without evicting any of it: bricks
  // streamed that no ray needs must not push out, now or in the passes after, those that one
  // does (thickness would become best effort). Boxes widened by a cell for the ray-caster's
  // float walk.
  std::vector<glm::uvec3> view;
  if (poolHoldsFrame(a.pages.size())) {
    const StoreHeader& header = mSource->header();
    const double brickWorld = header.cellSize * header.brickSize;
    for (std::size_t i = 0; i < a.pages.size(); ++i) {
      const glm::dvec3 lo = header.origin + glm::dvec3(a.index->bricks[i].coord) * brickWorld;
      if (a.pages[i] == kNotResident && boxMayBeInView(camera, mSettings.width, mSettings.height,
                                                       Box{lo - header.cellSize, lo + brickWorld + header.cellSize}))
        view.push_back(a.index->bricks[i].coord);
    }
  }
  // The whole view where it is at most twice the first pass's bricks: the passes after would
  // mostly find the rest behind them (a small frame's rays reach most of it), one pass each.
  // Beyond, the bricks that no ray reaches behind an opaque front would cost more than that.
  const std::vector<glm::uvec3>& coords = !view.empty() && view.size() <= 2 * first.size() ? view : first;
  // Where the pool cannot hold them with the frame's resident bricks, the passes stream what
  // the rays meet, as they come.
  if (frameResident + coords.size() > mPool.layout().slots) return;
  a.stats.bricksRequested += coords.size();
  mStreamer->request(coords);
  streamAndUpload(coords);
}

bool FrameRenderer::poolHoldsFrame(std::size_t frameBricks) const {
  const PoolLayout& layout = mPool.layout();
  if (frameBricks > layout.slots) return false;
  if (!layout.attributes) return true;
  // A brick has at most one attribute a stored cell, border included. Bricks of one frame that
  // take at most half the ring never wrap around onto their own, whatever the ring held.
  const std::uint64_t stored = mSource->header().brickSize + 2 * std::uint64_t(mOverlap);
  return 2 * frameBricks * stored * stored * stored <= layout.attributeCapacity;
}

bool FrameRenderer::growPool(std::uint64_t wanted) {
  const std::uint32_t slots = mPool.layout().slots;
  if (wanted <= slots || slots == mBudgetPool.slots) return false;
  // Nothing refers to the old pool once the device reallocates: not the frame begun before (its
  // page table), not the BrickPool. A device records its new layout last, so where allocating
  // throws, the empty BrickPool's first upload is refused rather than written out of bounds.
  mActive.reset();
  mPool = BrickPool(mBudgetPool.withSlots(std::max(wanted, 2 * std::uint64_t(slots))));
  mDevice->allocatePool(mPool.layout());
  return true;
}

void FrameRenderer::begin(int frame, const Camera& camera, int direction) {
  validate(camera, "camera");
  if (!mSource->hasFrame(frame)) throw InputError(mSource->name() + ": no frame " + std::to_string(frame));
  auto active = std::make_unique<ActiveFrame>();
  ActiveFrame& a = *active;
  a.frame = frame;
  a.index = mSource->frame(frame);
  const StoreHeader& header = mSource->header();
  a.stats.frameBricks = a.index->bricks.size();
  a.eyeInBricks = (camera.eye - header.origin) / (header.cellSize * header.brickSize);
  mStreamer->setFrame(frame, direction);
  mStreamer->setEye(a.eyeInBricks);
  a.failedBefore = mStreamer->stats().failed;
  a.pages = pageTable(*a.index);
  const std::size_t frameResident = std::ranges::count_if(a.pages, [](std::uint32_t p) { return p != kNotResident; });
  if (growPool(mPool.resident() + (a.index->bricks.size() - frameResident))) a.pages = pageTable(*a.index);
  a.stats.poolBytes = mPool.layout().bytes();
  mDevice->setOctree(a.index->octree.nodes);
  mDevice->setPageTable(a.pages);
  mDevice->beginImage(mSettings.width, mSettings.height);
  a.params = params(camera, *a.index);
  a.stats.bricksResident = mPool.resident();
  mActive = std::move(active);
}

const RenderStats& FrameRenderer::advance(double budgetMs, bool* changed) {
  FLIPSCOPE_CHECK(mActive, "FrameRenderer::advance() before begin()");
  const auto start = Clock::now();
  runPasses(false, budgetMs, changed);
  mActive->stats.totalMs += msSince(start);
  return mActive->stats;
}

bool FrameRenderer::finished() const { return mActive && mActive->finished; }

void FrameRenderer::runPasses(bool wait, double budgetMs, bool* changed) {
  ActiveFrame& a = *mActive;
  RenderStats& stats = a.stats;
  const auto start = Clock::now();
  if (changed) *changed = false;
  while (!a.finished) {
    if (a.traceDue) {
      a.traceDue = false;
      ++stats.passes;
      if (changed) *changed = true;
      const std::vector<std::uint32_t> requests = mDevice->trace(a.params);
      stats.traceMs += mDevice->lastTraceMs();
      if (requests.empty()) {
        stats.converged = true;
        a.finished = true;
        break;
      }
      if (stats.passes >= mSettings.maxPasses) {
        a.finished = true;
        break;
      }
      stats.bricksRequested += requests.size();
      std::vector<glm::uvec3> coords;
      coords.reserve(requests.size());
      for (std::uint32_t i : requests) {
        FLIPSCOPE_CHECK(i < a.index->bricks.size(), "request for brick " << i);
        coords.push_back(a.index->bricks[i].coord);
      }
      mStreamer->request(coords);
      if (wait) {
        streamAndUpload(coords);
        a.traceDue = true;
        continue;
      }
    }
    // Progressive: take what the Streamer has finished, a batch at a time while the slice has
    // time (uploads and foam classification count against the budget too), never wait for the
    // rest. A brick the pool could not place this time is requested again by the next pass.
    std::size_t taken = 0;
    do {
      const auto streamStart = Clock::now();
      auto ready = mStreamer->takeReady(kUploadBatch);
      taken = ready.size();
      if (mStreamer->stats().failed > a.failedBefore) mStreamer->rethrowLastError();
      std::erase_if(ready, [&](const auto& brick) {
        if (brick->key.frame != a.frame) return true;
        const std::int64_t i = a.index->octree.find(brick->key.coord);
        return i < 0 || a.pages[std::size_t(i)] != kNotResident;
      });
      stats.streamMs += msSince(streamStart);
      if (!ready.empty()) {
        upload(std::move(ready));
        a.traceDue = true;
      }
    } while (taken == kUploadBatch && msSince(start) < budgetMs);
    if (!a.traceDue || msSince(start) >= budgetMs) break;
  }
  stats.bricksResident = mPool.resident();
}

void FrameRenderer::streamAndUpload(const std::vector<glm::uvec3>& coords) {
  ActiveFrame& a = *mActive;
  // Convert (or fetch from the CPU cache) every requested brick before the next pass.
  const auto streamStart = Clock::now();
  std::unordered_set<BrickKey, BrickKeyHash> wanted;
  for (glm::uvec3 coord : coords) wanted.insert(BrickKey{a.frame, coord});
  std::vector<std::shared_ptr<const ConvertedBrick>> bricks;
  while (bricks.size() < wanted.size()) {
    mStreamer->waitIdle();
    auto ready = mStreamer->takeReady(wanted.size());
    if (mStreamer->stats().failed > a.failedBefore) mStreamer->rethrowLastError();
    if (ready.empty())
      throw LogicError("the streamer delivered " + std::to_string(bricks.size()) + " of " +
                       std::to_string(wanted.size()) + " requested bricks");
    for (auto& brick : ready)
      if (wanted.contains(brick->key)) bricks.push_back(std::move(brick));
  }
  a.stats.streamMs += msSince(streamStart);
  upload(std::move(bricks));
}

void FrameRenderer::upload(std::vector<std::shared_ptr<const ConvertedBrick>> bricks) {
  ActiveFrame& a = *mActive;
  RenderStats& stats = a.stats;
  // Upload nearest first: when the pool is too small for all, the front of the image goes first.
  const auto uploadStart = Clock::now();
  auto brickIndex = [&](const ConvertedBrick& b) { return a.index->octree.find(b.key.coord); };
  auto distance = [&](const ConvertedBrick& b) {
    const glm::dvec3 d = glm::dvec3(b.key.coord) + 0.5 - a.eyeInBricks;
    return glm::dot(d, d);
  };
  std::sort(bricks.begin(), bricks.end(), [&](const auto& x, const auto& y) {
    const double dx = distance(*x), dy = distance(*y);
    return dx != dy ? dx < dy : brickIndex(*x) < brickIndex(*y);
  });
  const std::uint64_t batch = ++mBatch;
  std::vector<std::uint32_t> uploadedSlots;
  std::vector<RaycastDevice::BrickUpload> uploads;
  std::vector<BrickKey> evicted;
  // A placement that throws (a brick larger than the ring) leaves the bricks placed before it
  // listed as resident: they are written before the error goes on, as they were when each
  // was uploaded as it was placed.
  const auto uploadPlaced = [&] { mDevice->uploadBricks(uploads); };
  for (const auto& brick : bricks) {
    evicted.clear();
    std::optional<BrickPool::Placement> placement;
    try {
      placement = mPool.place(brick->key, brick->bits.attributes.size(), batch, evicted);
    } catch (...) {
      uploadPlaced();
      throw;
    }
    for (const BrickKey& key : evicted) {
      ++stats.bricksEvicted;
      if (key.frame != a.frame) continue;
      a.pages[std::size_t(a.index->octree.find(key.coord))] = kNotResident;
      // The pool cannot hold what this frame needs at once: thickness behind a hit becomes
      // best effort, so the bricks of hits and of thickness marches cannot evict each other
      // forever. Hits stay exact.
      a.params.thicknessBestEffort = 1u;
    }
    if (!placement) break;  // the pool holds this pass's bricks only: the rest next pass
    uploads.push_back({placement->slot, placement->attributeOffset, brick.get()});
    a.pages[std::size_t(brickIndex(*brick))] = placement->slot;
    uploadedSlots.push_back(placement->slot);
    ++stats.bricksUploaded;
  }
  // One batch's placements never evict each other (BrickPool::place): the device may write
  // them all at once.
  uploadPlaced();
  mDevice->setPageTable(a.pages);
  stats.uploadMs += msSince(uploadStart);
  // §3.5: the bricks uploaded in this pass are classified in one batch before the next trace.
  if (mSettings.foam.mode != FoamMode::Keep && !uploadedSlots.empty()) {
    mDevice->classifyFoam(uploadedSlots, foamParams(uploadedSlots.size()));
    stats.foamMs += mDevice->lastClassifyMs();
    stats.bricksClassified += uploadedSlots.size();
  }
}

}  // namespace flipscope
