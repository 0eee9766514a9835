#include "smoothing/CpuScreenDevice.h"

#include <algorithm>
#include <thread>

#include <tbb/parallel_for.h>

#include "core/Error.h"

namespace flipscope {

std::string CpuScreenDevice::name() const {
  return "CPU reference (" + std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " threads)";
}

void CpuScreenDevice::setFrame(const ScreenFrame& frame) {
  const bool resized = frame.width != mFrame.width || frame.height != mFrame.height;
  mFrame = frame;
  if (!resized) return;
  for (Image& image : mImages)
    if (image.perPixel && !image.adopted) image.data.assign(frameElements(image.perPixel), glm::vec4(0));
}

ScreenImage CpuScreenDevice::createFrameImage(std::uint32_t perPixel) {
  FLIPSCOPE_CHECK(perPixel > 0);
  mImages.push_back({perPixel, std::vector<glm::vec4>(frameElements(perPixel), glm::vec4(0))});
  return ScreenImage(mImages.size() - 1);
}

std::vector<ScreenImage> CpuScreenDevice::createFrameImages(std::size_t count) {
  // The zeroing is most of the cost (the kernel's first touch of the pages): on every core.
  std::vector<std::vector<glm::vec4>> pixels(count);
  tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) { pixels[i].assign(frameElements(1), glm::vec4(0)); });
  std::vector<ScreenImage> images;
  for (auto& data : pixels) {
    mImages.push_back({1, std::move(data)});
    images.push_back(ScreenImage(mImages.size() - 1));
  }
  return images;
}

ScreenImage CpuScreenDevice::createFixedImage(std::size_t elements) {
  mImages.push_back({0, std::vector<glm::vec4>(elements, glm::vec4(0))});
  return ScreenImage(mImages.size() - 1);
}

CpuScreenDevice::Image& CpuScreenDevice::image(ScreenImage handle) {
  FLIPSCOPE_CHECK(handle < mImages.size(), "screen image " << handle);
  return mImages[handle];
}

ScreenImage CpuScreenDevice::adoptFramePixels(std::function<std::span<const glm::vec4>()> pixels,
                                              std::uint32_t perPixel) {
  FLIPSCOPE_CHECK(perPixel > 0 && pixels);
  mImages.push_back({perPixel, {}, std::move(pixels)});
  return ScreenImage(mImages.size() - 1);
}

CpuScreenDevice::Image& CpuScreenDevice::target(ScreenImage handle) {
  Image& target = image(handle);
  FLIPSCOPE_CHECK(!target.adopted, "screen image " << handle << " is adopted: an input only");
  // A frame image whose storage went to exchangePixels() gets its pixels back here.
  const std::size_t elements = frameElements(target.perPixel);
  if (target.perPixel && target.data.size() != elements) target.data.assign(elements, glm::vec4(0));
  return target;
}

std::span<const glm::vec4> CpuScreenDevice::read(ScreenImage handle) {
  const Image& source = image(handle);
  FLIPSCOPE_CHECK(source.adopted || !source.perPixel || source.data.size() == frameElements(source.perPixel),
                  "screen image " << handle << " read after exchangePixels() before a pass wrote it");
  return source.adopted ? source.adopted() : std::span<const glm::vec4>(source.data);
}

std::span<glm::vec4> CpuScreenDevice::pixels(ScreenImage handle) { return target(handle).data; }

void CpuScreenDevice::exchangePixels(ScreenImage handle, std::vector<glm::vec4>& pixels) {
  Image& image = target(handle);
  FLIPSCOPE_CHECK(image.perPixel > 0, "screen image " << handle << " is not a frame image");
  if (pixels.size() != image.data.size()) pixels.clear();  // sized by target() when written
  image.data.swap(pixels);
}

void CpuScreenDevice::upload(ScreenImage handle, std::span<const glm::vec4> data) {
  Image& image = target(handle);
  FLIPSCOPE_CHECK(data.size() == image.data.size(), data.size() << " != " << image.data.size());
  std::copy(data.begin(), data.end(), image.data.begin());
}

void CpuScreenDevice::downloadInto(ScreenImage handle, std::vector<glm::vec4>& pixels) {
  const auto source = read(handle);
  pixels.assign(source.begin(), source.end());
}

void CpuScreenDevice::run(const ScreenPass& pass, const void* params, std::size_t,
                          std::initializer_list<ScreenImage> inputs, ScreenImage output) {
  dispatch(pass, params, inputs, {output});
}

void CpuScreenDevice::runPair(const ScreenPass& pass, const void* params, std::size_t,
                              std::initializer_list<ScreenImage> inputs, ScreenImage output,
                              ScreenImage secondOutput) {
  FLIPSCOPE_CHECK(output != secondOutput, pass.kernel << ": both outputs are one image");
  dispatch(pass, params, inputs, {output, secondOutput});
}

void CpuScreenDevice::dispatch(const ScreenPass& pass, const void* params, std::initializer_list<ScreenImage> inputs,
                               std::initializer_list<ScreenImage> outputs) {
  FLIPSCOPE_CHECK(inputs.size() <= 4, pass.kernel << ": " << inputs.size() << " inputs");
  CpuPassInputs in;
  in.frame = mFrame;
  int slot = 0;
  for (ScreenImage handle : inputs) {
    for (ScreenImage output : outputs) FLIPSCOPE_CHECK(handle != output, pass.kernel << ": an output is also an input");
    const auto pixels = read(handle);
    in.images[slot] = pixels.data();
    in.sizes[slot] = pixels.size();
    ++slot;
  }
  glm::vec4* out[2] = {};
  int written = 0;
  for (ScreenImage output : outputs) {
    Image& image = target(output);
    FLIPSCOPE_CHECK(image.perPixel == 1, pass.kernel << ": an output must be a frame image");
    out[written++] = image.data.data();
  }
  pass.cpu(in, params, out[0], out[1]);
}

void CpuScreenDevice::clear(ScreenImage handle) {
  std::vector<glm::vec4>& data = target(handle).data;
  std::fill(data.begin(), data.end(), glm::vec4(0));
}

void CpuScreenDevice::copy(ScreenImage from, ScreenImage to) {
  const auto source = read(from);
  std::vector<glm::vec4>& destination = target(to).data;
  FLIPSCOPE_CHECK(source.size() == destination.size(), source.size() << " != " << destination.size());
  std::copy(source.begin(), source.end(), destination.begin());
}

}  // namespace flipscope
