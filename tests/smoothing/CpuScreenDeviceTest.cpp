// CpuScreenDevice's adopted images: passes read the caller's pixels where they are at each run,
// and nothing may write to them.
#include <gtest/gtest.h>

#include <vector>

#include "core/Error.h"
#include "smoothing/SmoothingScenes.h"
#include "smoothing/SurfaceNormals.h"

namespace flipscope {
namespace {

TEST(CpuScreenDevice, AdoptedPixelsAreReadWhereTheyAreAtEachRun) {
  const testing::DepthScene scene = testing::sphereScene(64, 48);
  CpuScreenDevice device;
  device.setFrame(scene.frame);
  std::vector<glm::vec4> outside = scene.depth;
  const ScreenImage adopted = device.adoptFramePixels([&] { return std::span<const glm::vec4>(outside); }, 1);
  const ScreenImage uploaded = device.createFrameImage(), a = device.createFrameImage(),
                    b = device.createFrameImage();
  device.upload(uploaded, scene.depth);
  reconstructNormals(device, adopted, a);
  reconstructNormals(device, uploaded, b);
  EXPECT_EQ(device.download(a), device.download(b));
  EXPECT_EQ(device.download(adopted), outside);
  // The owner changes its pixels (and may move them): the next run reads the new ones.
  std::vector<glm::vec4> flat(outside.size(), glm::vec4(0));
  outside.swap(flat);
  reconstructNormals(device, adopted, a);
  EXPECT_NE(device.download(a), device.download(b));
  // An adopted image is an input only.
  EXPECT_THROW(device.upload(adopted, scene.depth), LogicError);
  EXPECT_THROW(device.clear(adopted), LogicError);
  EXPECT_THROW(device.copy(uploaded, adopted), LogicError);
  EXPECT_THROW(reconstructNormals(device, uploaded, adopted), LogicError);
}

}  // namespace
}  // namespace flipscope
