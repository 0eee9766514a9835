// DisplayTexture: the image the viewer shows, a float RGBA texture the size of the render,
// filled from the pipeline's display image: copied on the device from its storage buffer (the
// GPU pipeline, nothing read back) or uploaded from host memory (the CPU pipeline). Needs a
// current context (OpenGL 3.3 for upload(), 4.5 for copyFrom()); move-only.
#pragma once

#include <epoxy/gl.h>

#include <cstdint>
#include <span>

#include <glm/vec4.hpp>

namespace flipscope::gl {
class Buffer;
}

namespace flipscope::viewer {

class DisplayTexture {
 public:
  DisplayTexture();
  ~DisplayTexture();
  DisplayTexture(const DisplayTexture&) = delete;
  DisplayTexture& operator=(const DisplayTexture&) = delete;

  /// Rows of `width` x `height` rgba pixels, row 0 at the top (shown at the top).
  void upload(std::span<const glm::vec4> pixels, std::uint32_t width, std::uint32_t height);
  /// The same from a shader storage buffer of width * height vec4 (after the passes that wrote it).
  void copyFrom(const gl::Buffer& buffer, std::uint32_t width, std::uint32_t height);

  GLuint id() const { return mId; }
  std::uint32_t width() const { return mWidth; }
  std::uint32_t height() const { return mHeight; }

 private:
  void ensureSize(std::uint32_t width, std::uint32_t height);
  GLuint mId = 0;
  std::uint32_t mWidth = 0, mHeight = 0;
};

}  // namespace flipscope::viewer
