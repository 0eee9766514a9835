// GpuRaycaster: the compute ray-caster on OpenGL 4.5 (raycast/glsl/Raycast.comp) and the foam
// classification (raycast/glsl/FoamClassify.comp), with its brick pool in shader storage buffers (Reichl et al. 2014 §3.3, §4.1). Headless through EGL: the
// NVIDIA device platform on GPU machines, Mesa (llvmpipe) elsewhere.
#pragma once

#include <memory>

#include "raycast/RaycastDevice.h"
#include "gl/EglContext.h"
#include "gl/Objects.h"

namespace flipscope {

class GpuRaycaster : public RaycastDevice {
 public:
  /// Creates a headless EGL context and compiles the shader. Throws gl::Unavailable without a
  /// usable EGL/OpenGL 4.5 device.
  GpuRaycaster();
  /// Tag: run in the context the caller made current (a window's), which it keeps alive and
  /// current while the ray-caster is used and destroyed.
  struct AdoptCurrentContext {};
  /// Adopts the OpenGL 4.5 context current on this thread and compiles the shader there. Throws
  /// gl::Unavailable when that context is below OpenGL 4.5.
  explicit GpuRaycaster(AdoptCurrentContext);
  ~GpuRaycaster() override;

  std::string name() const override;
  /// Mesa's llvmpipe or softpipe: OpenGL on the CPU.
  bool isSoftwareRenderer() const { return mSoftware; }
  std::uint64_t maxBufferBytes() const override { return mMaxBufferBytes; }
  void allocatePool(const PoolLayout& layout) override;
  void setOctree(std::span<const OctreeNode> nodes) override;
  void setPageTable(std::span<const std::uint32_t> pageTable) override;
  void uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) override;
  void classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) override;
  double lastClassifyMs() const override { return mLastClassifyMs; }
  std::vector<glm::uvec4> readFoam(std::uint32_t slot) override;
  void beginImage(std::uint32_t width, std::uint32_t height) override;
  std::vector<std::uint32_t> trace(const RaycastParams& params) override;
  double lastTraceMs() const override { return mLastTraceMs; }
  std::vector<RayHit> readHits() override;
  /// The image's rays on the device (RayHit array, row 0 at the top), for the passes after the
  /// ray-caster; the object stays the same across images (its storage is reallocated on resize).
  const gl::Buffer& hitBuffer() const { return mHits; }

 private:
  explicit GpuRaycaster(gl::EglContext context);

  gl::EglContext mContext;  ///< empty when the context is adopted (name() says "window")
  gl::Program mProgram;
  gl::Program mFoamProgram;       ///< raycast/glsl/FoamClassify.comp, compiled on first use
  gl::Program mOccupancyProgram;  ///< raycast/glsl/FoamOccupancy.comp, likewise
  gl::TimerQuery mTimer;
  std::uint64_t mMaxBufferBytes = 0;
  PoolLayout mLayout;
  std::uint32_t mWidth = 0, mHeight = 0;
  std::size_t mBricks = 0;  ///< bricks of the current frame (page table entries)
  gl::Buffer mParams, mNodes, mPages, mSubBricks, mMips, mAttributeBases, mAttributes, mHits, mRequests, mRequestFlags;
  gl::Buffer mFoam, mFoamOccupancy, mFoamParams, mBatch;
  double mLastTraceMs = 0;
  double mLastClassifyMs = 0;
  bool mSoftware = false;  ///< Mesa llvmpipe/softpipe: timer queries return ~0, passes are timed on the wall clock
};

enum class DeviceChoice { Auto, Gpu, Cpu, CpuReference };

/// The device a command asked for: Gpu (OpenGL, llvmpipe included; throws gl::Unavailable
/// without a context), Cpu (TiledCpuRaycaster, the fast one), CpuReference (CpuRaycaster, the
/// exact reference), or Auto (OpenGL on a hardware GPU, else the fast CPU ray-caster, which
/// beats llvmpipe many times over; `fallbackReason` says why).
std::unique_ptr<RaycastDevice> createRaycastDevice(DeviceChoice choice, std::string* fallbackReason = nullptr);

}  // namespace flipscope
