// Defaults that give a closed surface on a real cache: a Blender Mantaflow FLIP frame converted
// and rendered with no options has no holes inside the liquid body, where the old defaults
// (1024 cells along the domain, spheres of one cell) gave a see-through cloud.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <string>

#include "TestSupport.h"
#include "pipeline/ImageWriter.h"

namespace {

using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

struct Coverage {
  std::size_t foreground = 0;
  /// Pixels of small holes: background regions enclosed by foreground (not reached from the
  /// image border) of fewer than kSmallHole pixels, the gaps between particles a see-through
  /// cloud shows. Larger enclosed regions are dry spots of the simulation itself.
  std::size_t holes = 0;
  double holeFraction() const { return foreground ? double(holes) / double(foreground) : 1.0; }
};
constexpr std::size_t kSmallHole = 40;  // pixels at 320x180, where a particle spans about 6 pixels across

/// The small holes of the image (4-connected background regions).
Coverage measureHoles(const flipscope::RenderImage& image) {
  const int w = int(image.width), h = int(image.height);
  std::vector<char> background(std::size_t(w) * h), reached(std::size_t(w) * h, 0);
  Coverage c;
  // The liquid, or the volumetric foam over it (§3.5: a foam cell is no sphere; the foam that
  // covers it is in the foam layer).
  for (std::size_t i = 0; i < background.size(); ++i) {
    background[i] = !std::isfinite(image.depth[i]) && (image.foam.empty() || image.foam[i].a < 0.01f);
    c.foreground += !background[i];
  }
  std::deque<int> queue;
  auto push = [&](int x, int y) {
    const int i = y * w + x;
    if (background[i] && !reached[i]) {
      reached[i] = 1;
      queue.push_back(i);
    }
  };
  for (int x = 0; x < w; ++x) push(x, 0), push(x, h - 1);
  for (int y = 0; y < h; ++y) push(0, y), push(w - 1, y);
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    const int x = i % w, y = i / w;
    if (x > 0) push(x - 1, y);
    if (x + 1 < w) push(x + 1, y);
    if (y > 0) push(x, y - 1);
    if (y + 1 < h) push(x, y + 1);
  }
  // Enclosed regions by size.
  for (std::size_t start = 0; start < background.size(); ++start) {
    if (!background[start] || reached[start]) continue;
    std::vector<int> region;
    reached[start] = 1;
    queue.push_back(int(start));
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      region.push_back(i);
      const int x = i % w, y = i / w;
      if (x > 0) push(x - 1, y);
      if (x + 1 < w) push(x + 1, y);
      if (y > 0) push(x, y - 1);
      if (y + 1 < h) push(x, y + 1);
    }
    if (region.size() < kSmallHole) c.holes += region.size();
  }
  return c;
}

Coverage coverageOfRender(const flipscope::testing::TempDir& dir, const std::string& name,
                          const std::string& convertOptions, const std::string& renderOptions) {
  const std::string vdb = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb").string();
  const std::string store = (dir.path() / name).string(), image = (dir.path() / (name + ".exr")).string();
  CommandRun convert = runFlipscope("convert " + vdb + " -o " + store + " -q " + convertOptions);
  EXPECT_EQ(convert.exitCode, 0) << convert.output;
  CommandRun render = runFlipscope("render " + store + " -o " + image + " --up z --size 320x180 -q " + renderOptions);
  EXPECT_EQ(render.exitCode, 0) << render.output;
  return measureHoles(flipscope::readExr(image).image);
}

TEST(SurfaceDefaults, MantaflowFrameRendersClosedWithDefaultSettings) {
  flipscope::testing::TempDir dir("surface-defaults");
  const Coverage defaults = coverageOfRender(dir, "defaults", "", "");
  EXPECT_GT(defaults.foreground, 320u * 180u / 20) << "the default camera frames the liquid";
  EXPECT_LT(defaults.holeFraction(), 0.001) << defaults.holes << " hole pixels in " << defaults.foreground;
  std::printf("defaults: %zu small-hole pixels in %zu foreground pixels\n", defaults.holes, defaults.foreground);
  // Without foam classification every particle is a sphere: the surface alone is closed.
  const Coverage spheres = coverageOfRender(dir, "keep", "", "--foam keep");
  EXPECT_LT(spheres.holeFraction(), 0.001) << spheres.holes << " hole pixels in " << spheres.foreground;
  std::printf("--foam keep: %zu small-hole pixels in %zu foreground pixels\n", spheres.holes, spheres.foreground);

  // The old defaults leave the body full of holes: the measure sees them. (Spheres of a quarter
  // particle spacing touch no neighbour: the classification would take every one for foam.)
  const Coverage old = coverageOfRender(dir, "old", "--resolution 1024", "--radius 1 --foam keep");
  std::printf("old defaults: %zu small-hole pixels in %zu foreground pixels\n", old.holes, old.foreground);
  EXPECT_GT(old.holeFraction(), 0.02) << old.holes << " hole pixels in " << old.foreground;
}

}  // namespace
