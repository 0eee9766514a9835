// CpuScreenDevice: the C++ reference of the screen-space passes. Each pass runs its shared kernel
// compiled as C++ (smoothing/detail/CpuScreenKernel.h) over images held in plain arrays, one TBB
// task per band of rows.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "smoothing/ScreenDevice.h"

namespace flipscope {

class CpuScreenDevice : public ScreenDevice {
 public:
  std::string name() const override;
  void setFrame(const ScreenFrame& frame) override;
  ScreenImage createFrameImage(std::uint32_t perPixel = 1) override;
  std::vector<ScreenImage> createFrameImages(std::size_t count) override;
  ScreenImage createFixedImage(std::size_t elements) override;
  void upload(ScreenImage image, std::span<const glm::vec4> data) override;
  void downloadInto(ScreenImage image, std::vector<glm::vec4>& pixels) override;
  void clear(ScreenImage image) override;
  void copy(ScreenImage from, ScreenImage to) override;
  void run(const ScreenPass& pass, const void* params, std::size_t paramBytes,
           std::initializer_list<ScreenImage> inputs, ScreenImage output) override;
  void runPair(const ScreenPass& pass, const void* params, std::size_t paramBytes,
               std::initializer_list<ScreenImage> inputs, ScreenImage output, ScreenImage secondOutput) override;

  /// The image's elements in place (no copy), for callers on the CPU; not of an adopted image.
  /// Writable: an image whose storage went to exchangePixels() comes back zeroed (read() checks
  /// that it was written again instead).
  std::span<glm::vec4> pixels(ScreenImage image);
  /// Moves the frame image's pixels into `pixels` (no copy) and takes the vector's storage in
  /// their place: its contents are undefined until a pass writes the image. Storage of another
  /// size (none, the first time) is not sized here but when the image is next written: a single
  /// frame's render never allocates it.
  void exchangePixels(ScreenImage image, std::vector<glm::vec4>& pixels);
  /// An image that passes read where `pixels` says it is, at each run (the CPU ray-caster's
  /// hits, `perPixel` vec4 a pixel): nothing is copied. It is an input only.
  ScreenImage adoptFramePixels(std::function<std::span<const glm::vec4>()> pixels, std::uint32_t perPixel);

 private:
  struct Image {
    std::uint32_t perPixel = 0;  ///< 0: fixed size
    std::vector<glm::vec4> data;
    std::function<std::span<const glm::vec4>()> adopted;  ///< set: the pixels are elsewhere
  };
  Image& image(ScreenImage handle);
  /// The vec4 of a frame image of `perPixel` vec4 a pixel, at the current frame's size.
  std::size_t frameElements(std::uint32_t perPixel) const { return std::size_t(width()) * height() * perPixel; }
  /// An image that is written to (not adopted).
  Image& target(ScreenImage handle);
  std::span<const glm::vec4> read(ScreenImage handle);
  /// run and runPair; `outputs` holds one image or two.
  void dispatch(const ScreenPass& pass, const void* params, std::initializer_list<ScreenImage> inputs,
                std::initializer_list<ScreenImage> outputs);
  std::vector<Image> mImages;
};

}  // namespace flipscope
