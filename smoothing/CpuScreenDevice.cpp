#include "smoothing/CpuScreenDevice.h"

#include <algorithm>
#include <thread>

#include "core/Error.h"

namespace flipscope {

std::string CpuScreenDevice::name() const {
  return "CPU reference (" + std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " threads)";
}

void CpuScreenDevice::setFrame(const ScreenFrame& frame) {
  const bool resized = frame.size.x != mFrame.size.x || frame.size.y != mFrame.size.y;
  mFrame = frame;
  if (!resized) return;
  for (Image& image : mImages)
    if (image.perPixel) image.data.assign(std::size_t(frame.size.x) * frame.size.y * image.perPixel, glm::vec4(0));
}

ScreenImage CpuScreenDevice::createFrameImage(std::uint32_t perPixel) {
  FLIPSCOPE_CHECK(perPixel > 0);
  mImages.push_back({perPixel, std::vector<glm::vec4>(std::size_t(width()) * height() * perPixel, glm::vec4(0))});
  return ScreenImage(mImages.size() - 1);
}

ScreenImage CpuScreenDevice::createFixedImage(std::size_t elements) {
  mImages.push_back({0, std::vector<glm::vec4>(elements, glm::vec4(0))});
  return ScreenImage(mImages.size() - 1);
}

CpuScreenDevice::Image& CpuScreenDevice::image(ScreenImage handle) {
  FLIPSCOPE_CHECK(handle < mImages.size(), "screen image " << handle);
  return mImages[handle];
}

std::span<glm::vec4> CpuScreenDevice::pixels(ScreenImage handle) { return image(handle).data; }

void CpuScreenDevice::upload(ScreenImage handle, std::span<const glm::vec4> data) {
  Image& target = image(handle);
  FLIPSCOPE_CHECK(data.size() == target.data.size(), data.size() << " != " << target.data.size());
  std::copy(data.begin(), data.end(), target.data.begin());
}

std::vector<glm::vec4> CpuScreenDevice::download(ScreenImage handle) { return image(handle).data; }

void CpuScreenDevice::run(const ScreenPass& pass, const void* params, std::size_t,
                          std::initializer_list<ScreenImage> inputs, ScreenImage output) {
  FLIPSCOPE_CHECK(inputs.size() <= 4, pass.kernel << ": " << inputs.size() << " inputs");
  CpuPassInputs in;
  in.frame = mFrame;
  int slot = 0;
  for (ScreenImage handle : inputs) {
    FLIPSCOPE_CHECK(handle != output, pass.kernel << ": the output is also an input");
    const Image& source = image(handle);
    in.images[slot] = source.data.data();
    in.sizes[slot] = source.data.size();
    ++slot;
  }
  Image& target = image(output);
  FLIPSCOPE_CHECK(target.perPixel == 1, pass.kernel << ": the output must be a frame image");
  pass.cpu(in, params, target.data.data());
}

void CpuScreenDevice::clear(ScreenImage handle) {
  std::vector<glm::vec4>& data = image(handle).data;
  std::fill(data.begin(), data.end(), glm::vec4(0));
}

void CpuScreenDevice::copy(ScreenImage from, ScreenImage to) {
  const std::vector<glm::vec4>& source = image(from).data;
  std::vector<glm::vec4>& target = image(to).data;
  FLIPSCOPE_CHECK(source.size() == target.size(), source.size() << " != " << target.size());
  std::copy(source.begin(), source.end(), target.begin());
}

}  // namespace flipscope
