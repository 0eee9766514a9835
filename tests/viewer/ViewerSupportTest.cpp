// The viewer's cache store names and its frame-time history.
#include <gtest/gtest.h>

#include "viewer/CacheConversion.h"
#include "viewer/FrameTimeHistory.h"

namespace flipscope::viewer {
namespace {

TEST(CacheStorePath, IsBesideTheFirstInputNamedWithoutItsPattern) {
  EXPECT_EQ(cacheStorePath({"cache/fluid_####.vdb"}, {}), std::filesystem::path("cache/fluid.store"));
  EXPECT_EQ(cacheStorePath({"sim/splash.$F4.bgeo.sc"}, {}), std::filesystem::path("sim/splash.store"));
  EXPECT_EQ(cacheStorePath({"a/fluid_data_0030.vdb", "b/p.vdb"}, {}), std::filesystem::path("a/fluid_data_0030.store"));
  EXPECT_EQ(cacheStorePath({"a/p_%04d.ply"}, "/tmp/c"), std::filesystem::path("/tmp/c/p.store"));
  EXPECT_EQ(cacheStorePath({"####.ply"}, {}), std::filesystem::path("cache.store"));
}

TEST(FrameTimeHistory, KeepsTheLastSeconds) {
  FrameTimeHistory history(1.0);
  for (int i = 0; i <= 20; ++i) history.add(i * 0.1, i == 3 ? 250.0 : 10.0, std::uint64_t(i));
  EXPECT_EQ(history.frames(), 21u);
  // Frames within 1 s of the last (t = 2.0): t = 1.0 .. 2.0, 11 of them.
  EXPECT_EQ(history.frameMs().size(), 11u);
  EXPECT_EQ(history.bricksUploaded().front(), 10.0f);
  EXPECT_EQ(history.frameMs().front(), 10.0f);
  EXPECT_NEAR(history.fps(), 10.0, 1e-9);
}

}  // namespace
}  // namespace flipscope::viewer
