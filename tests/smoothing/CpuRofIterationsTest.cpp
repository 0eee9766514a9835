// The ROF filter's iterations on the CPU device (smoothing/detail/CpuRofIterations.h, compact
// images, one sweep an iteration) give the result of its passes run one by one on the same
// device, bit for bit: the passes are run here through a ScreenDevice that forwards to a
// CpuScreenDevice but is not one, so RofFilter takes its general path; and from frame to frame.
#include <gtest/gtest.h>

#include <vector>

#include "smoothing/CpuScreenDevice.h"
#include "smoothing/SmoothingScenes.h"
#include "smoothing/SurfaceFilter.h"

namespace flipscope {
namespace {

/// Every call to `inner`: a ScreenDevice that is not a CpuScreenDevice.
class ForwardingScreenDevice : public ScreenDevice {
 public:
  std::string name() const override { return "forwarding to " + mInner.name(); }
  void setFrame(const ScreenFrame& frame) override {
    mFrame = frame;
    mInner.setFrame(frame);
  }
  ScreenImage createFrameImage(std::uint32_t perPixel) override { return mInner.createFrameImage(perPixel); }
  ScreenImage createFixedImage(std::size_t elements) override { return mInner.createFixedImage(elements); }
  void upload(ScreenImage image, std::span<const glm::vec4> data) override { mInner.upload(image, data); }
  void downloadInto(ScreenImage image, std::vector<glm::vec4>& pixels) override { mInner.downloadInto(image, pixels); }
  void clear(ScreenImage image) override { mInner.clear(image); }
  void copy(ScreenImage from, ScreenImage to) override { mInner.copy(from, to); }
  void run(const ScreenPass& pass, const void* params, std::size_t paramBytes, std::initializer_list<ScreenImage> inputs,
           ScreenImage output) override {
    mInner.run(pass, params, paramBytes, inputs, output);
  }
  void runPair(const ScreenPass& pass, const void* params, std::size_t paramBytes,
               std::initializer_list<ScreenImage> inputs, ScreenImage output, ScreenImage secondOutput) override {
    mInner.runPair(pass, params, paramBytes, inputs, output, secondOutput);
  }

 private:
  CpuScreenDevice mInner;
};

std::vector<glm::vec4> smooth(ScreenDevice& device, const testing::DepthScene& scene, const SmoothingOptions& options) {
  device.setFrame(scene.frame);
  const ScreenImage depth = device.createFrameImage(), output = device.createFrameImage();
  device.upload(depth, scene.depth);
  createSurfaceFilter(options)->apply(device, depth, output);
  return device.download(output);
}

TEST(CpuRofIterations, EqualThePassesRunOneByOne) {
  // Odd sizes, so that the last band of rows is short; a sphere over a plane and a sphere alone
  // (background around the domain, runs that start and end mid-row).
  const testing::DepthScene scenes[] = {testing::sphereScene(97, 61, 0.5f, 3.0f, 0.8f, 4.0f, 3),
                                        testing::sphereScene(64, 37, 0.8f, 2.5f, 0.6f, 0.0f, 5)};
  for (const testing::DepthScene& scene : scenes) {
    for (int iterations : {1, 2, 17, 75}) {
      for (float strength : {0.5f, 3.0f}) {
        SCOPED_TRACE(::testing::Message() << scene.frame.width << "x" << scene.frame.height << ", " << iterations
                                          << " iterations, strength " << strength);
        const SmoothingOptions options{.name = "rof", .iterations = iterations, .strength = strength};
        CpuScreenDevice cpu;
        ForwardingScreenDevice passes;
        const std::vector<glm::vec4> fast = smooth(cpu, scene, options), reference = smooth(passes, scene, options);
        ASSERT_EQ(fast.size(), reference.size());
        int differing = 0;
        for (std::size_t i = 0; i < fast.size(); ++i) differing += fast[i] != reference[i];
        EXPECT_EQ(differing, 0);
        // The filter did something: the smoothed depth is not the input.
        int changed = 0;
        for (std::size_t i = 0; i < fast.size(); ++i) changed += scene.depth[i].y > 0.5f && fast[i].x != scene.depth[i].x;
        EXPECT_GT(changed, int(fast.size() / 20));
      }
    }
  }
}

TEST(CpuRofIterations, OneFilterKeepsNothingFromItsLastFrame) {
  // The filter keeps its compact images from frame to frame: a frame of another size and another
  // domain, then the first again, must each give what a fresh filter gives.
  const testing::DepthScene scenes[] = {testing::sphereScene(97, 61, 0.5f, 3.0f, 0.8f, 4.0f, 3),
                                        testing::sphereScene(64, 37, 0.8f, 2.5f, 0.6f, 0.0f, 5),
                                        testing::sphereScene(97, 61, 0.5f, 3.0f, 0.8f, 4.0f, 3)};
  const SmoothingOptions options{.name = "rof", .iterations = 17, .strength = 3.0f};
  CpuScreenDevice cpu;
  const auto filter = createSurfaceFilter(options);
  for (const testing::DepthScene& scene : scenes) {
    SCOPED_TRACE(::testing::Message() << scene.frame.width << "x" << scene.frame.height);
    cpu.setFrame(scene.frame);
    const ScreenImage depth = cpu.createFrameImage(), output = cpu.createFrameImage();
    cpu.upload(depth, scene.depth);
    filter->apply(cpu, depth, output);
    ForwardingScreenDevice passes;
    EXPECT_EQ(cpu.download(output), smooth(passes, scene, options));
  }
}

}  // namespace
}  // namespace flipscope
