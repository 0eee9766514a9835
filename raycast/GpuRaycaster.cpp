#include "raycast/GpuRaycaster.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "gl/ShaderSource.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/TiledCpuRaycaster.h"

namespace flipscope {

namespace {
// Binding points of raycast/glsl/Raycast.comp.
enum Binding : GLuint {
  kParams = 0,
  kNodes = 1,
  kPages = 2,
  kSubBricks = 3,
  kMips = 4,
  kAttributeBases = 5,
  kAttributes = 6,
  kHits = 7,
  kRequests = 8,
  kRequestFlags = 9,
  kFoam = 10,
  kBatch = 11,  // FoamClassify.comp: the batch's slots
  kFoamOccupancy = 12,
};
constexpr std::uint32_t kGroupSize = 8;      // local_size_x and _y of Raycast.comp
constexpr std::uint32_t kFoamGroupSize = 64;  // local_size_x of FoamClassify.comp

/// A buffer of at least `bytes` (GL refuses empty storage; unused bindings get 16 bytes).
/// Data shorter than 16 bytes is copied into a zeroed block first: GL reads the whole storage
/// size from `data` (ASan found the overread of a one-node octree).
gl::Buffer makeBuffer(std::uint64_t bytes, const void* data = nullptr) {
  constexpr std::uint64_t kMinimum = 16;
  if (bytes >= kMinimum) return gl::Buffer(bytes, data);
  std::array<std::byte, kMinimum> padded{};
  if (data && bytes) std::memcpy(padded.data(), data, std::size_t(bytes));
  return gl::Buffer(kMinimum, data ? padded.data() : nullptr);
}
}  // namespace

GpuRaycaster::GpuRaycaster() : GpuRaycaster(gl::EglContext::create()) {}

GpuRaycaster::GpuRaycaster(AdoptCurrentContext) : GpuRaycaster(gl::EglContext{}) {}

GpuRaycaster::GpuRaycaster(gl::EglContext context) : mContext(std::move(context)) {
  if (!mContext.isValid()) gl::requireCurrentGl45("GpuRaycaster");
  mProgram = gl::Program::compute(gl::shaderSource("Raycast.comp"));
  GLint64 maxBlock = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
  mMaxBufferBytes = std::uint64_t(maxBlock);
  // llvmpipe answers timer queries with ~0: time its passes on the wall clock instead.
  mSoftware = gl::isSoftwareRenderer(gl::currentRenderer());
  mParams = makeBuffer(sizeof(RaycastParams));
  mFoam = makeBuffer(0);  // bound by every trace; a pool without foam never reads them
  mFoamOccupancy = makeBuffer(0);
}

GpuRaycaster::~GpuRaycaster() = default;

std::string GpuRaycaster::name() const {
  return "OpenGL (" + (mContext.isValid() ? mContext.platform() : std::string("window")) + "): " + gl::currentRenderer();
}

void GpuRaycaster::allocatePool(const PoolLayout& layout) {
  mLayout = PoolLayout{};  // no slots until every buffer is made (RaycastDevice's contract)
  for (gl::Buffer* buffer : {&mSubBricks, &mMips, &mAttributeBases, &mAttributes, &mFoam, &mFoamOccupancy})
    *buffer = gl::Buffer();  // let the old ones go first
  mSubBricks = makeBuffer(std::uint64_t(layout.slots) * layout.subBricksPerSlot * 16);
  mMips = makeBuffer(std::uint64_t(layout.slots) * layout.mipWordsPerSlot * 4);
  mAttributeBases = makeBuffer(layout.attributes ? std::uint64_t(layout.slots) * layout.subBricksPerSlot * 4 : 0);
  mAttributes = makeBuffer(layout.attributeCapacity * 2);
  mFoam = makeBuffer(layout.foam ? std::uint64_t(layout.slots) * layout.subBricksPerSlot * 16 : 0);
  mFoamOccupancy = makeBuffer(layout.foam ? std::uint64_t(layout.slots) * layout.foamOccupancyWords() * 4 : 0);
  mLayout = layout;
}

void GpuRaycaster::setOctree(std::span<const OctreeNode> nodes) {
  mNodes = makeBuffer(nodes.size_bytes(), nodes.data());
}

void GpuRaycaster::setPageTable(std::span<const std::uint32_t> pageTable) {
  if (pageTable.size() != mBricks || mPages.size() < std::max<std::size_t>(pageTable.size_bytes(), 16)) {
    mBricks = pageTable.size();
    mPages = makeBuffer(pageTable.size_bytes(), pageTable.data());
    mRequests = makeBuffer(4 + pageTable.size_bytes());  // count, then up to one entry per brick
    mRequestFlags = makeBuffer(pageTable.size_bytes());
    return;
  }
  if (!pageTable.empty()) mPages.upload(0, pageTable.data(), pageTable.size_bytes());
}

void GpuRaycaster::uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) {
  FLIPSCOPE_CHECK(slot < mLayout.slots && brick.bits.subBricks.size() == mLayout.subBricksPerSlot &&
                  brick.mipmap.size() == mLayout.mipWordsPerSlot);
  mSubBricks.upload(std::uint64_t(slot) * mLayout.subBricksPerSlot * 16, brick.bits.subBricks.data(),
                    brick.bits.subBricks.size() * 16);
  mMips.upload(std::uint64_t(slot) * mLayout.mipWordsPerSlot * 4, brick.mipmap.data(), brick.mipmap.size() * 4);
  if (mLayout.attributes) {
    const auto bases = attributeBases(brick.bits, attributeOffset);
    mAttributeBases.upload(std::uint64_t(slot) * mLayout.subBricksPerSlot * 4, bases.data(), bases.size() * 4);
    if (!brick.bits.attributes.empty())
      mAttributes.upload(attributeOffset * 2, brick.bits.attributes.data(), brick.bits.attributes.size() * 2);
  }
  if (mLayout.foam) {
    const std::uint64_t offset = std::uint64_t(slot) * mLayout.subBricksPerSlot * 16;
    if (brick.foamKinds.empty()) {
      mFoam.clearZero(offset, std::uint64_t(mLayout.subBricksPerSlot) * 16);
    } else {
      FLIPSCOPE_CHECK(brick.foamKinds.size() == mLayout.subBricksPerSlot);
      mFoam.upload(offset, brick.foamKinds.data(), brick.foamKinds.size() * 16);
    }
  }
}

void GpuRaycaster::classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) {
  FLIPSCOPE_CHECK(mLayout.foam && params.subBricksPerSlot == mLayout.subBricksPerSlot &&
                  params.batchSubBricks == slots.size() * mLayout.subBricksPerSlot);
  mLastClassifyMs = 0;
  if (slots.empty()) return;
  if (!mFoamProgram.id()) {
    mFoamProgram = gl::Program::compute(gl::shaderSource("FoamClassify.comp"));
    mOccupancyProgram = gl::Program::compute(gl::shaderSource("FoamOccupancy.comp"));
  }
  if (!mFoamParams.id()) mFoamParams = makeBuffer(sizeof(FoamClassifyParams));
  // Bricks of the batch along y, in chunks that the dispatch limit allows (GL guarantees 65535
  // work groups per axis).
  constexpr std::size_t kMaxChunk = 65535;
  const std::size_t chunk = std::min(slots.size(), kMaxChunk);
  if (mBatch.size() < chunk * 4) mBatch = makeBuffer(std::max<std::uint64_t>(chunk * 4, 4096));
  const auto start = std::chrono::steady_clock::now();
  mTimer.begin();
  for (std::size_t first = 0; first < slots.size(); first += kMaxChunk) {
    const std::size_t count = std::min(kMaxChunk, slots.size() - first);
    FoamClassifyParams p = params;
    p.batchSubBricks = std::uint32_t(count) * mLayout.subBricksPerSlot;
    mFoamParams.upload(0, &p, sizeof(p));
    mBatch.upload(0, slots.data() + first, count * 4);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT);
    mFoamParams.bindBase(GL_UNIFORM_BUFFER, kParams);
    mSubBricks.bindBase(GL_SHADER_STORAGE_BUFFER, kSubBricks);
    mFoam.bindBase(GL_SHADER_STORAGE_BUFFER, kFoam);
    mBatch.bindBase(GL_SHADER_STORAGE_BUFFER, kBatch);
    mFoamOccupancy.bindBase(GL_SHADER_STORAGE_BUFFER, kFoamOccupancy);
    if (params.classify != 0u) {
      mFoamProgram.use();
      mFoamProgram.dispatch((mLayout.subBricksPerSlot + kFoamGroupSize - 1) / kFoamGroupSize, std::uint32_t(count), 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    mOccupancyProgram.use();
    mOccupancyProgram.dispatch((mLayout.foamOccupancyWords() + kFoamGroupSize - 1) / kFoamGroupSize,
                               std::uint32_t(count), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
  mTimer.end();
  if (mSoftware) glFinish();
  mLastClassifyMs = mSoftware ? msSince(start) : mTimer.milliseconds();
}

std::vector<glm::uvec4> GpuRaycaster::readFoam(std::uint32_t slot) {
  FLIPSCOPE_CHECK(mLayout.foam && slot < mLayout.slots);
  std::vector<glm::uvec4> foam(mLayout.subBricksPerSlot);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  mFoam.download(std::uint64_t(slot) * mLayout.subBricksPerSlot * 16, foam.size() * 16, foam.data());
  return foam;
}

void GpuRaycaster::beginImage(std::uint32_t width, std::uint32_t height) {
  mWidth = width;
  mHeight = height;
  const std::uint64_t bytes = std::uint64_t(width) * height * sizeof(RayHit);
  if (mHits.size() != bytes) mHits = makeBuffer(bytes);
  mHits.clearZero();  // zeros: fresh pending rays, cleared on the device (no upload)
}

std::vector<std::uint32_t> GpuRaycaster::trace(const RaycastParams& params) {
  FLIPSCOPE_CHECK(params.width == mWidth && params.height == mHeight);
  mParams.upload(0, &params, sizeof(params));
  const std::uint32_t zero = 0;
  mRequests.upload(0, &zero, 4);
  mRequestFlags.clearZero();
  mParams.bindBase(GL_UNIFORM_BUFFER, kParams);
  mNodes.bindBase(GL_SHADER_STORAGE_BUFFER, kNodes);
  mPages.bindBase(GL_SHADER_STORAGE_BUFFER, kPages);
  mSubBricks.bindBase(GL_SHADER_STORAGE_BUFFER, kSubBricks);
  mMips.bindBase(GL_SHADER_STORAGE_BUFFER, kMips);
  mAttributeBases.bindBase(GL_SHADER_STORAGE_BUFFER, kAttributeBases);
  mAttributes.bindBase(GL_SHADER_STORAGE_BUFFER, kAttributes);
  mHits.bindBase(GL_SHADER_STORAGE_BUFFER, kHits);
  mRequests.bindBase(GL_SHADER_STORAGE_BUFFER, kRequests);
  mRequestFlags.bindBase(GL_SHADER_STORAGE_BUFFER, kRequestFlags);
  mFoam.bindBase(GL_SHADER_STORAGE_BUFFER, kFoam);
  mFoamOccupancy.bindBase(GL_SHADER_STORAGE_BUFFER, kFoamOccupancy);
  mProgram.use();
  const auto start = std::chrono::steady_clock::now();
  mTimer.begin();
  mProgram.dispatch((mWidth + kGroupSize - 1) / kGroupSize, (mHeight + kGroupSize - 1) / kGroupSize, 1);
  mTimer.end();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  std::uint32_t count = 0;
  mRequests.download(0, 4, &count);
  count = std::min<std::uint32_t>(count, std::uint32_t(mBricks));
  std::vector<std::uint32_t> requests(count);
  if (count) mRequests.download(4, count * 4, requests.data());
  std::sort(requests.begin(), requests.end());
  requests.erase(std::unique(requests.begin(), requests.end()), requests.end());
  mLastTraceMs = mSoftware ? msSince(start) : mTimer.milliseconds();
  return requests;
}

std::vector<RayHit> GpuRaycaster::readHits() {
  std::vector<RayHit> hits(std::size_t(mWidth) * mHeight);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  mHits.download(0, hits.size() * sizeof(RayHit), hits.data());
  return hits;
}

std::unique_ptr<RaycastDevice> createRaycastDevice(DeviceChoice choice, std::string* fallbackReason) {
  if (choice == DeviceChoice::Cpu) return std::make_unique<TiledCpuRaycaster>();
  if (choice == DeviceChoice::CpuReference) return std::make_unique<CpuRaycaster>();
  try {
    auto gpu = std::make_unique<GpuRaycaster>();
    if (choice == DeviceChoice::Auto && gpu->isSoftwareRenderer()) {
      if (fallbackReason)
        *fallbackReason = "the OpenGL renderer is software (" + gpu->name() + "), slower than the CPU";
      return std::make_unique<TiledCpuRaycaster>();
    }
    return gpu;
  } catch (const gl::Unavailable& e) {
    if (choice == DeviceChoice::Gpu) throw;
    if (fallbackReason) *fallbackReason = e.what();
    return std::make_unique<TiledCpuRaycaster>();
  }
}

}  // namespace flipscope
