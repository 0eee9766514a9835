// GpuScreenDevice: the screen-space passes as OpenGL 4.5 compute shaders over shader storage
// buffers, in the context that is current when it is created (the ray-caster's, so its images
// never leave the device). Programs are compiled once per (shader, kernel). Destroy it while its
// context is alive and current.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gl/Objects.h"
#include "smoothing/ScreenDevice.h"

namespace flipscope {

class GpuScreenDevice : public ScreenDevice {
 public:
  /// Needs a current OpenGL 4.5 context. `name` describes it ("OpenGL (device): ...").
  explicit GpuScreenDevice(std::string name);
  ~GpuScreenDevice() override;

  std::string name() const override { return mName; }
  void setFrame(const ScreenFrame& frame) override;
  ScreenImage createFrameImage(std::uint32_t perPixel = 1) override;
  ScreenImage createFixedImage(std::size_t elements) override;
  /// An image that is an existing buffer of `perPixel` vec4 per pixel, owned by the caller (the
  /// ray-caster's hit buffer); it must stay alive and frame-sized while passes read it.
  ScreenImage adoptFrameBuffer(const gl::Buffer* buffer, std::uint32_t perPixel);
  void upload(ScreenImage image, std::span<const glm::vec4> data) override;
  void downloadInto(ScreenImage image, std::vector<glm::vec4>& pixels) override;
  void clear(ScreenImage image) override;
  void copy(ScreenImage from, ScreenImage to) override;
  void run(const ScreenPass& pass, const void* params, std::size_t paramBytes,
           std::initializer_list<ScreenImage> inputs, ScreenImage output) override;
  void runPair(const ScreenPass& pass, const void* params, std::size_t paramBytes,
               std::initializer_list<ScreenImage> inputs, ScreenImage output, ScreenImage secondOutput) override;
  void finish() override;
  /// The shader storage buffer behind `image` (the viewer copies its display image from it).
  const gl::Buffer& buffer(ScreenImage image) const;

 private:
  struct Image {
    std::uint32_t perPixel = 0;  ///< 0: fixed size
    std::size_t elements = 0;
    gl::Buffer owned;
    const gl::Buffer* adopted = nullptr;
    const gl::Buffer& buffer() const { return adopted ? *adopted : owned; }
  };
  Image& image(ScreenImage handle);
  const gl::Program& program(const ScreenPass& pass);
  /// run and runPair; `outputs` holds one image or two.
  void dispatch(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                std::initializer_list<ScreenImage> inputs, std::initializer_list<ScreenImage> outputs);

  std::string mName;
  std::vector<Image> mImages;
  std::map<std::pair<std::string, std::string>, gl::Program> mPrograms;
  gl::Buffer mFrameBlock;
  gl::Buffer mPassBlock;
};

}  // namespace flipscope
