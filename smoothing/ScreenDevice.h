// ScreenDevice: where the screen-space stages run (Reichl et al. 2014 §3.3 Fig. 3, §3.4, §3.6):
// smoothing, normal reconstruction and shading are sequences of passes over vec4 images, and each
// pass is one per-pixel kernel written once in shared GLSL (smoothing/glsl/, core/GlslShared.h).
// GpuScreenDevice runs a pass as a compute shader; CpuScreenDevice runs the same kernel compiled
// as C++ (the reference the tests compare it with). Stage code (filters, normals, shading) is
// written once against this interface, so both devices run the same sequence of passes.
//
// Images are device-owned arrays of vec4, identified by a ScreenImage handle. A frame-sized image
// holds `perPixel` vec4 per pixel and is reallocated (contents undefined) when setFrame changes
// the size; a fixed image keeps its element count. Not thread safe.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "smoothing/ScreenTypes.h"

namespace flipscope {

using ScreenImage = std::uint32_t;

class CpuScreenDevice;
struct CpuPassInputs;

/// One per-pixel kernel: on the GPU the embedded compute shader `shader` with FS_KERNEL defined as
/// `kernel`; on the CPU `cpu`, the same kernel compiled as C++ (see detail/CpuScreenKernel.h).
/// A kernel returns a vec4 (ScreenDevice::run), or a ScreenPair (runPair; its .comp includes
/// ScreenPairPassMain.glsl).
struct ScreenPass {
  std::string_view shader;  ///< embedded .comp, e.g. "Rof.comp"
  std::string_view kernel;  ///< its kernel function, e.g. "rofDual"
  /// Writes the kernel's value for every pixel of the frame into `output` (a pair's first value;
  /// its second into `secondOutput`, null for a vec4 kernel); `params` is the pass's parameter
  /// struct (the block at binding 1).
  void (*cpu)(const CpuPassInputs& inputs, const void* params, glm::vec4* output, glm::vec4* secondOutput);
};

class ScreenDevice {
 public:
  virtual ~ScreenDevice() = default;
  /// e.g. "OpenGL: ..." or "CPU reference (2 threads)".
  virtual std::string name() const = 0;
  /// The frame (size and camera) of the following passes; reallocates frame-sized images when
  /// the size changes.
  virtual void setFrame(const ScreenFrame& frame) = 0;
  const ScreenFrame& frame() const { return mFrame; }
  std::uint32_t width() const { return mFrame.width; }
  std::uint32_t height() const { return mFrame.height; }

  /// A frame-sized image of `perPixel` vec4 per pixel.
  virtual ScreenImage createFrameImage(std::uint32_t perPixel = 1) = 0;
  /// `count` frame-sized images of one vec4 per pixel (the CPU device zeroes them on every core).
  virtual std::vector<ScreenImage> createFrameImages(std::size_t count) {
    std::vector<ScreenImage> images;
    for (std::size_t i = 0; i < count; ++i) images.push_back(createFrameImage());
    return images;
  }
  /// An image of `elements` vec4 that keeps its size (an environment map).
  virtual ScreenImage createFixedImage(std::size_t elements) = 0;
  /// Writes the whole image (data.size() equals its element count).
  virtual void upload(ScreenImage image, std::span<const glm::vec4> data) = 0;
  /// Reads the whole image into `pixels`, resized to its element count; a vector kept from
  /// frame to frame keeps its memory (no fresh pages to fault in for each frame's read-back).
  virtual void downloadInto(ScreenImage image, std::vector<glm::vec4>& pixels) = 0;
  std::vector<glm::vec4> download(ScreenImage image) {
    std::vector<glm::vec4> pixels;
    downloadInto(image, pixels);
    return pixels;
  }
  /// Sets every element to zero.
  virtual void clear(ScreenImage image) = 0;
  /// Copies `from` into `to` (same element count).
  virtual void copy(ScreenImage from, ScreenImage to) = 0;
  /// Runs `pass` on every pixel of the frame: inputs (at most four) are read through
  /// ssLoad/ssLoadIndex in the order given, the result goes to `output` (frame-sized, not one of
  /// the inputs). `params` is the pass's parameter struct of `paramBytes` bytes.
  virtual void run(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                   std::initializer_list<ScreenImage> inputs, ScreenImage output) = 0;
  /// As run, for a pass whose kernel returns a ScreenPair: its first value goes to `output`, its
  /// second to `secondOutput` (frame-sized, neither an input nor `output`). Where two values of a
  /// pixel come from the same inputs, one pass reads them once.
  virtual void runPair(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                       std::initializer_list<ScreenImage> inputs, ScreenImage output, ScreenImage secondOutput) = 0;
  /// Waits until every pass issued so far has finished (for timing stages).
  virtual void finish() {}

  template <class Params>
  void run(const ScreenPass& pass, const Params& params, std::initializer_list<ScreenImage> inputs,
           ScreenImage output) {
    run(pass, &params, sizeof(Params), inputs, output);
  }
  template <class Params>
  void runPair(const ScreenPass& pass, const Params& params, std::initializer_list<ScreenImage> inputs,
               ScreenImage output, ScreenImage secondOutput) {
    runPair(pass, &params, sizeof(Params), inputs, output, secondOutput);
  }

 protected:
  ScreenFrame mFrame{};
};

/// The pixels (vec4) of a frame of `width` x `height` a CPU pass reads, and the frame block.
struct CpuPassInputs {
  ScreenFrame frame;
  const glm::vec4* images[4] = {};
  std::size_t sizes[4] = {};
};

}  // namespace flipscope
