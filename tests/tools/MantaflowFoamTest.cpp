// The bundled Blender Mantaflow frame with its FLIP and its secondary particles together (issue
// 9, Reichl et al. 2014 §3.5): converted and rendered with no options, the liquid surface shows
// where the FLIP particles alone put it (the secondary particles' foam and spray are foam, their
// bubbles hidden). Frame 9 is the sample's frame of most bubbles (2909 bubble cells beside 5787
// liquid ones, `info`), 377 foam and 652 spray cells.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "TestSupport.h"
#include "pipeline/ImageWriter.h"

namespace {

using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

const std::string kFlip9 = flipscope::testing::mantaflowFile("data", "fluid_data_0009.vdb").string();
const std::string kSecondary9 = flipscope::testing::mantaflowFile("particles", "fluid_particles_0009.vdb").string();

flipscope::RenderImage convertAndRender(const flipscope::testing::TempDir& dir, const std::string& name,
                                        const std::string& inputs, const std::string& renderOptions) {
  const std::string store = (dir.path() / name).string(), image = (dir.path() / (name + ".exr")).string();
  CommandRun convert = runFlipscope("convert " + inputs + " -o " + store + " -q");
  EXPECT_EQ(convert.exitCode, 0) << convert.output;
  // One camera for every render: the FLIP frame's default view, from a camera file.
  const std::string camera = (dir.path() / "camera.json").string();
  CommandRun render = runFlipscope("render " + store + " -o " + image + " --up z --size 320x180 -q --camera-file " +
                                   camera + " " + renderOptions);
  EXPECT_EQ(render.exitCode, 0) << render.output;
  return flipscope::readExr(image).image;
}

/// Of the pixels where the FLIP particles alone show the surface, the fraction where `image`
/// shows it within `tolerance` world units of that depth.
double surfaceAgreement(const flipscope::RenderImage& flip, const flipscope::RenderImage& image, double tolerance) {
  std::size_t body = 0, near = 0;
  for (std::size_t i = 0; i < flip.depth.size(); ++i) {
    if (!std::isfinite(flip.depth[i])) continue;
    ++body;
    near += std::isfinite(image.depth[i]) && std::abs(image.depth[i] - flip.depth[i]) < tolerance;
  }
  return body ? double(near) / double(body) : 0.0;
}

TEST(MantaflowFoam, FlipAndSecondaryParticlesShowTheLiquidSurface) {
  flipscope::testing::TempDir dir("mantaflow-foam");
  // The camera of the FLIP frame's default render.
  {
    const std::string store = (dir.path() / "camera-store").string();
    ASSERT_EQ(runFlipscope("convert " + kFlip9 + " -o " + store + " -q").exitCode, 0);
    CommandRun camera = runFlipscope("render " + store + " -o " + (dir.path() / "c.png").string() +
                                     " --up z --size 320x180 -q --save-camera " + (dir.path() / "camera.json").string());
    ASSERT_EQ(camera.exitCode, 0) << camera.output;
  }
  const flipscope::RenderImage flip = convertAndRender(dir, "flip", kFlip9, "--foam keep");
  const flipscope::RenderImage both = convertAndRender(dir, "both", kFlip9 + " " + kSecondary9, "");
  const flipscope::RenderImage secondary =
      convertAndRender(dir, "secondary", kSecondary9, "--foam keep --bubbles show");
  // One particle spacing (0.0307 world units). The bubbles fill the body, so their own surface lies
  // near the liquid's; at three spacings it would pass for it in 71% of the pixels.
  constexpr double kTolerance = 0.0307;
  const double withFoam = surfaceAgreement(flip, both, kTolerance);
  const double secondaryOnly = surfaceAgreement(flip, secondary, kTolerance);
  std::printf("surface within %.2f of the FLIP-only depth: %.0f%% with the secondary particles (defaults), %.0f%% "
              "for the secondary particles alone as spheres\n",
              kTolerance, 100 * withFoam, 100 * secondaryOnly);
  EXPECT_GT(withFoam, 0.8) << "the liquid surface shows";
  EXPECT_LT(secondaryOnly, 0.6) << "the measure tells the secondary particles' own surface from the liquid's";
  ASSERT_FALSE(both.foam.empty());
  double foam = 0;
  for (const glm::vec4& f : both.foam) foam = std::max(foam, double(f.a));
  EXPECT_GT(foam, 0.15) << "the foam and spray are rendered as foam";
}

}  // namespace

namespace {

TEST(MantaflowFoam, FoamSourceAndBubbleOptionsChangeTheImage) {
  flipscope::testing::TempDir dir("mantaflow-foam-options");
  const std::string store = (dir.path() / "store").string();
  ASSERT_EQ(runFlipscope("convert " + kFlip9 + " " + kSecondary9 + " -o " + store + " -q").exitCode, 0);
  const auto render = [&](const std::string& name, const std::string& options) {
    const std::string image = (dir.path() / (name + ".exr")).string();
    CommandRun r = runFlipscope("render " + store + " -o " + image + " --up z --size 160x90 -q " + options);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return flipscope::readExr(image).image;
  };
  const auto sum = [](const std::vector<float>& values) {
    double s = 0;
    for (float v : values) s += std::isfinite(v) ? v : 0;
    return s;
  };
  double foamDifference = 0;
  const auto kind = render("kind", "--foam-from kind"), classify = render("classify", "--foam-from classify");
  for (std::size_t i = 0; i < kind.foam.size(); ++i) foamDifference += std::abs(kind.foam[i].a - classify.foam[i].a);
  EXPECT_GT(foamDifference, 1.0) << "the stored kinds are not the classification";
  // Bubbles lie inside the body: shown, they add to the liquid the thickness trace meets.
  const auto hidden = render("hidden", "--foam keep"), shown = render("shown", "--foam keep --bubbles show");
  EXPECT_GT(sum(shown.thickness), sum(hidden.thickness) * 1.01);
  CommandRun bad = runFlipscope("render " + store + " -o " + (dir.path() / "x.png").string() + " --bubbles pop");
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.output.find("valid values: hide, show"), std::string::npos) << bad.output;
}

}  // namespace
