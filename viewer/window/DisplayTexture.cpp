#include "viewer/window/DisplayTexture.h"

#include "core/Error.h"
#include "gl/Objects.h"

namespace flipscope::viewer {

DisplayTexture::DisplayTexture() {
  glGenTextures(1, &mId);
  glBindTexture(GL_TEXTURE_2D, mId);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  ensureSize(1, 1);
}

DisplayTexture::~DisplayTexture() {
  if (mId) glDeleteTextures(1, &mId);
}

void DisplayTexture::ensureSize(std::uint32_t width, std::uint32_t height) {
  if (width == mWidth && height == mHeight) return;
  glBindTexture(GL_TEXTURE_2D, mId);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, GLsizei(width), GLsizei(height), 0, GL_RGBA, GL_FLOAT, nullptr);
  mWidth = width;
  mHeight = height;
}

void DisplayTexture::upload(std::span<const glm::vec4> pixels, std::uint32_t width, std::uint32_t height) {
  FLIPSCOPE_CHECK(pixels.size() == std::size_t(width) * height, pixels.size() << " pixels for " << width << "x" << height);
  ensureSize(width, height);
  glBindTexture(GL_TEXTURE_2D, mId);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(width), GLsizei(height), GL_RGBA, GL_FLOAT, pixels.data());
}

void DisplayTexture::copyFrom(const gl::Buffer& buffer, std::uint32_t width, std::uint32_t height) {
  FLIPSCOPE_CHECK(buffer.size() >= std::uint64_t(width) * height * 16, "display buffer " << buffer.size());
  ensureSize(width, height);
  glMemoryBarrier(GL_PIXEL_BUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer.id());
  glBindTexture(GL_TEXTURE_2D, mId);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(width), GLsizei(height), GL_RGBA, GL_FLOAT, nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

}  // namespace flipscope::viewer
