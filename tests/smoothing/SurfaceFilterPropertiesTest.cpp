// Properties every surface filter shares, on the CPU reference: one suite over the names of
// surfaceFilters() (the registry, so a new filter must get a row in kExpectations). Where the
// filters differ (the settings a property is tested at, thresholds, the scene that shows their
// smoothing) the row of the table below says so; 'none' skips what needs smoothing. What is
// particular to one filter lives in its own <Name>FilterTest.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;
using testing::kBackgroundDepth;
using testing::smoothOnCpu;

/// Strength and iterations of a test run (-1: the filter's default).
struct Setting {
  float strength = -1;
  int iterations = -1;
};

std::ostream& operator<<(std::ostream& out, const Setting& s) {
  return out << "strength " << s.strength << ", iterations " << s.iterations;
}

std::vector<Setting> atStrengths(std::initializer_list<float> strengths, int iterations = -1) {
  std::vector<Setting> settings;
  for (float s : strengths) settings.push_back({s, iterations});
  return settings;
}

std::vector<Setting> atIterations(std::initializer_list<int> iterations, float strength = -1) {
  std::vector<Setting> settings;
  for (int i : iterations) settings.push_back({strength, i});
  return settings;
}

/// A scene and a measure of its roughness that a filter's smoothing shows on.
enum class Roughened {
  Sphere,  ///< sphereScene(96, 72, 1): a rough sphere on the background, measured by depthRoughness
  Plane,   ///< roughPlaneScene(): a rough plane facing the eye, measured by noiseRoughness
};

/// Settings along which the roughness falls: each run's roughness is below `factor` times the
/// previous run's (the first run's below `factor` times the input's).
struct SmoothingSequence {
  Roughened scene = Roughened::Sphere;
  std::vector<Setting> settings;  ///< empty: not tested
  double factor = 0;
};

/// A rough sphere (optionally in front of a plane) that the filter brings closer to the analytic
/// depth: the RMS error over the pixels of normal z >= minFacing falls below errorFactor times the
/// input's, and (noiseFactor > 0) noiseRoughness below noiseFactor times the input's.
struct AccuracyCase {
  Setting setting;
  std::uint32_t width = 96, height = 72;
  std::vector<float> roughness;  ///< bump heights, particle radii: one run each
  float planeDepth = 0;          ///< 0: the sphere alone
  float minFacing = -2;          ///< -2: every foreground pixel
  double errorFactor = 0;
  double noiseFactor = 0;
};

/// One filter's row: what each test expects of it.
struct Expectations {
  std::string_view name;
  // RegistryDefaultsAndRanges: the documented defaults and the largest values.
  int defaultIterations, maxIterations;
  float defaultStrength, maxStrength;
  // ConstantDepthIsAFixedPoint: depth 5 on the whole frame and (constantOnDisk) on a disk moves
  // by at most constantTolerance (world units) at every setting.
  std::vector<Setting> constantSettings;
  bool constantOnDisk;
  float constantTolerance;
  // BackgroundPixelsAreNeverWritten
  Setting backgroundSetting;
  // DepthStepBetweenTwoSurfacesSurvives: both planes stay within stepTolerance of their depth,
  // the front one may bend back by stepFrontBendRadii particle radii more.
  std::vector<Setting> stepSettings;
  float stepTolerance;
  float stepFrontBendRadii;
  // LargerStrengthSmoothsMore, MoreIterationsSmoothMore
  SmoothingSequence strengths, iterations;
  // SmoothedSphereComesCloserToTheAnalyticDepth
  std::vector<AccuracyCase> accuracy;
};

const std::vector<Expectations> kExpectations = {
    {.name = "rof",
     .defaultIterations = 75,
     .maxIterations = 10000,
     .defaultStrength = 8.0f,
     .maxStrength = 1000.0f,
     // p stays 0 on a constant depth, so u = v exactly.
     .constantSettings = {{8.0f}},
     .constantOnDisk = true,
     .constantTolerance = 0.0f,
     .backgroundSetting = {8.0f},
     // Total variation rounds the edge off by a little more than a bump.
     .stepSettings = {Setting{}},
     .stepTolerance = 0.03f,
     .stepFrontBendRadii = 0,
     .strengths = {Roughened::Sphere, atStrengths({0.5f, 2.0f, 8.0f}), 0.9},
     .iterations = {Roughened::Plane, atIterations({1, 2, 4, 8, 20, 60, 200}), 0.9},
     // The default (8) flattens the sphere's cap; a gentler strength approaches the sphere.
     .accuracy = {{.setting = {2.0f},
                   .width = 160,
                   .height = 120,
                   .roughness = {1.0f},
                   .minFacing = 0.5f,
                   .errorFactor = 0.7,
                   .noiseFactor = 0.3}}},
    {.name = "bilateral",
     .defaultIterations = 1,
     .maxIterations = 10,
     .defaultStrength = 4.0f,
     .maxStrength = 16.0f,
     .constantSettings = {{8.0f, 1}, {8.0f, 3}},
     .constantOnDisk = true,
     .constantTolerance = 2e-6f,
     .backgroundSetting = {8.0f, 3},
     // The range Gaussian (sigma 2 radii at the default) gives the other plane no weight.
     .stepSettings = {{8.0f, 3}},
     .stepTolerance = 0.02f,
     .stepFrontBendRadii = 0,
     .strengths = {Roughened::Sphere, atStrengths({2.0f, 4.0f, 8.0f}), 0.9},
     .iterations = {Roughened::Sphere, atIterations({1, 2, 4}), 0.9},
     .accuracy = {{.roughness = {0.5f, 1.0f}, .planeDepth = 5.0f, .errorFactor = 0.7}}},
    {.name = "narrow-range",
     .defaultIterations = 4,
     .maxIterations = 20,
     .defaultStrength = 3.0f,
     .maxStrength = 16.0f,
     // On a disk the rim is pulled back (NarrowRangeFilter.SilhouetteIsPulledBackByAtMostMu).
     .constantSettings = {{8.0f, 1}, {8.0f, 4}},
     .constantOnDisk = false,
     .constantTolerance = 2e-6f,
     .backgroundSetting = {8.0f, 6},
     // The rear plane ignores the front one; the front one counts the rear one as its own depth
     // + mu, so every pass moves its edge back by a part of mu: a few mu after 8 iterations.
     .stepSettings = {{}, {16.0f, 8}},
     .stepTolerance = 0.02f,
     .stepFrontBendRadii = 3,
     .strengths = {Roughened::Sphere, atStrengths({3.0f, 6.0f, 12.0f}), 0.9},
     .iterations = {Roughened::Sphere, atIterations({1, 2, 4, 8}), 0.95},
     // Where the sphere faces the eye; the rim band:
     // NarrowRangeFilter.RimEndsAboutAParticleRadiusOffTheAnalyticDepth.
     .accuracy = {{.roughness = {0.5f, 1.0f}, .minFacing = 0.8f, .errorFactor = 0.7}}},
    {.name = "curvature-flow",
     .defaultIterations = 60,
     .maxIterations = 1000,
     .defaultStrength = 0.5f,
     .maxStrength = 1.0f,
     // Every difference of a constant depth is 0, so is the curvature.
     .constantSettings = {{0.5f, 100}, {1.0f, 100}},
     .constantOnDisk = true,
     .constantTolerance = 0.0f,
     .backgroundSetting = {1.0f, 200},
     .stepSettings = {{1.0f, 200}},
     .stepTolerance = 0.02f,
     .stepFrontBendRadii = 0,
     // The flow's fixed point is the plane itself, so the roughness keeps falling.
     .strengths = {Roughened::Plane, atStrengths({0.1f, 0.3f, 0.6f, 1.0f}, 20), 0.8},
     .iterations = {Roughened::Plane, atIterations({5, 20, 60, 200}, 0.5f), 0.8},
     // 160 x 120: a sphere of about 90 pixels across, bumps of one particle radius (~1.1 pixels).
     .accuracy = {{.width = 160,
                   .height = 120,
                   .roughness = {1.0f},
                   .minFacing = 0.5f,
                   .errorFactor = 0.7,
                   .noiseFactor = 0.3}}},
    {.name = "plane-fit",
     .defaultIterations = 2,
     .maxIterations = 50,
     .defaultStrength = 2.0f,
     .maxStrength = 50.0f,
     // Up to float rounding of the eye-space positions (an ulp of 5 is 4.8e-7).
     .constantSettings = {{4.0f, 10}, {50.0f, 10}},
     .constantOnDisk = true,
     .constantTolerance = 2e-6f,
     .backgroundSetting = {50.0f, 10},
     .stepSettings = {{8.0f, 10}},
     .stepTolerance = 0.02f,
     .stepFrontBendRadii = 0,
     .strengths = {Roughened::Plane, atStrengths({1.0f, 2.0f, 4.0f, 8.0f}, 3), 0.9},
     .iterations = {Roughened::Plane, atIterations({1, 2, 3, 5, 10}, 4.0f), 0.9},
     .accuracy = {{.width = 160,
                   .height = 120,
                   .roughness = {1.0f},
                   .minFacing = 0.5f,
                   .errorFactor = 0.7,
                   .noiseFactor = 0.3}}},
    {.name = "none",
     .defaultIterations = 0,
     .maxIterations = 0,
     .defaultStrength = 0.0f,
     .maxStrength = 0.0f,
     .constantSettings = {Setting{}},
     .constantOnDisk = true,
     .constantTolerance = 0.0f,
     .backgroundSetting = {},
     .stepSettings = {Setting{}},
     .stepTolerance = 0.02f,  // the bumps themselves
     .stepFrontBendRadii = 0,
     .strengths = {},
     .iterations = {},
     .accuracy = {}},
};

class SurfaceFilterProperties : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    for (const Expectations& e : kExpectations)
      if (e.name == GetParam()) mExpect = &e;
    ASSERT_NE(mExpect, nullptr) << "no row for filter '" << GetParam() << "' in kExpectations";
  }
  SmoothingOptions options(const Setting& s) const {
    return testing::filterOptions(GetParam(), s.strength, s.iterations);
  }
  /// Runs `sequence` on its scene: each setting must smooth more than the one before.
  void expectFalling(const SmoothingSequence& sequence) const {
    if (sequence.settings.empty()) GTEST_SKIP() << GetParam() << " does not smooth";
    const bool sphere = sequence.scene == Roughened::Sphere;
    const DepthScene s = sphere ? testing::sphereScene(96, 72, 1.0f) : testing::roughPlaneScene();
    auto roughness = [&](const std::vector<glm::vec4>& d) {
      return sphere ? testing::depthRoughness(d, s) : testing::noiseRoughness(d, s);
    };
    double previous = roughness(s.depth);
    for (const Setting& setting : sequence.settings) {
      const double r = roughness(smoothOnCpu(s, options(setting)));
      EXPECT_LT(r, previous * sequence.factor) << setting;
      previous = r;
    }
  }
  const Expectations* mExpect = nullptr;
};

TEST_P(SurfaceFilterProperties, RegistryDefaultsAndRanges) {
  const Expectations& e = *mExpect;
  const SmoothingOptions defaults = resolve({GetParam()});
  EXPECT_EQ(defaults.iterations, e.defaultIterations);
  EXPECT_EQ(defaults.strength, e.defaultStrength);
  const SurfaceFilterInfo& info = testing::filterInfo(GetParam());
  EXPECT_EQ(info.maxIterations, e.maxIterations);
  EXPECT_EQ(info.maxStrength, e.maxStrength);
  EXPECT_EQ(info.minStrength, 0.0f);
  EXPECT_NO_THROW(resolve(options({-1, e.maxIterations})));
  EXPECT_NO_THROW(resolve(options({e.maxStrength})));
  EXPECT_NO_THROW(resolve(options({e.maxStrength, e.maxIterations})));
  EXPECT_NO_THROW(resolve(options({0.0f, 0})));
  EXPECT_THROW(resolve(options({-1, e.maxIterations + 1})), InputError);
  EXPECT_THROW(resolve(options({-1, -2})), InputError);
  EXPECT_THROW(resolve(options({std::nextafter(e.maxStrength, 2 * e.maxStrength + 1)})), InputError);
  EXPECT_THROW(resolve(options({-3.0f})), InputError);
}

TEST_P(SurfaceFilterProperties, ConstantDepthIsAFixedPoint) {
  const Expectations& e = *mExpect;
  for (bool disk : {false, true}) {
    if (disk && !e.constantOnDisk) continue;
    const DepthScene s = testing::constantScene(disk);
    for (const Setting& setting : e.constantSettings) {
      const auto out = smoothOnCpu(s, options(setting));
      for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i].y, s.depth[i].y) << i;
      EXPECT_LE(testing::worstChange(out, s), e.constantTolerance) << setting << (disk ? ", disk" : "");
    }
  }
}

TEST_P(SurfaceFilterProperties, BackgroundPixelsAreNeverWritten) {
  const DepthScene s = testing::sphereScene(96, 72, 1.0f);
  const auto out = smoothOnCpu(s, options(mExpect->backgroundSetting));
  int background = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].y, s.depth[i].y);
    if (s.depth[i].y < 0.5f) {
      ++background;
      ASSERT_EQ(out[i].x, kBackgroundDepth) << i;
    }
  }
  EXPECT_GT(background, 1000);
}

TEST_P(SurfaceFilterProperties, ZeroStrengthOrIterationsLeaveTheDepth) {
  const DepthScene s = testing::sphereScene(96, 72, 1.0f);
  for (const Setting& setting : {Setting{0.0f, -1}, Setting{-1, 0}}) {
    const auto out = smoothOnCpu(s, options(setting));
    for (std::size_t i = 0; i < out.size(); ++i) {
      ASSERT_EQ(out[i].x, s.depth[i].x) << setting << ", pixel " << i;
      ASSERT_EQ(out[i].y, s.depth[i].y) << setting << ", pixel " << i;
    }
  }
}

TEST_P(SurfaceFilterProperties, DepthStepBetweenTwoSurfacesSurvives) {
  // testing::depthStepScene: rough planes at depth 3 (columns up to 47) and 3.5 (from 48 on).
  const Expectations& e = *mExpect;
  const DepthScene s = testing::depthStepScene();
  const float tolerance = e.stepTolerance, bend = e.stepFrontBendRadii * s.frame.particleRadius;
  for (const Setting& setting : e.stepSettings) {
    const auto out = smoothOnCpu(s, options(setting));
    for (int y = 0; y < 72; ++y) {
      auto at = [&](int x) { return out[y * 96 + x].x; };
      EXPECT_GT(at(48) - at(47), 0.45f) << setting << ", row " << y;
      EXPECT_GT(at(49) - at(46), 0.45f) << setting << ", row " << y;
      EXPECT_GT(at(47), 3.0f - tolerance) << setting << ", row " << y;
      EXPECT_LT(at(47), 3.0f + tolerance + bend) << setting << ", row " << y;
      EXPECT_NEAR(at(48), 3.5f, tolerance) << setting << ", row " << y;
    }
  }
}

TEST_P(SurfaceFilterProperties, LargerStrengthSmoothsMore) { expectFalling(mExpect->strengths); }

TEST_P(SurfaceFilterProperties, MoreIterationsSmoothMore) { expectFalling(mExpect->iterations); }

TEST_P(SurfaceFilterProperties, StableAtTheDefaultAndTheLargestSettings) {
  // A rough sphere in front of a rough plane: silhouettes, steep rims and pixel-sized noise.
  const DepthScene s = testing::sphereScene(128, 72, 2.0f, 3.0f, 0.8f, 5.0f);
  const auto [lo, hi] = testing::foregroundRange(s.depth, s);
  const double rough = testing::noiseRoughness(s.depth, s);
  for (const Setting& setting : {Setting{}, Setting{mExpect->maxStrength, mExpect->maxIterations}}) {
    const auto out = smoothOnCpu(s, options(setting));
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out[i].x)) << setting << ", pixel " << i;
    const auto [outLo, outHi] = testing::foregroundRange(out, s);
    EXPECT_GE(outLo, lo - 0.01f) << setting;
    EXPECT_LE(outHi, hi + 0.01f) << setting;
    if (GetParam() != "none") {
      EXPECT_LT(testing::noiseRoughness(out, s), rough * 0.5) << setting;
    }
  }
}

TEST_P(SurfaceFilterProperties, SmoothedSphereComesCloserToTheAnalyticDepth) {
  if (mExpect->accuracy.empty()) GTEST_SKIP() << GetParam() << " does not smooth";
  for (const AccuracyCase& c : mExpect->accuracy)
    for (float roughness : c.roughness) {
      const DepthScene s = testing::sphereScene(c.width, c.height, roughness, 3.0f, 0.8f, c.planeDepth);
      const auto out = smoothOnCpu(s, options(c.setting));
      EXPECT_LT(testing::rmsError(out, s, c.minFacing), c.errorFactor * testing::rmsError(s.depth, s, c.minFacing))
          << c.setting << ", roughness " << roughness;
      if (c.noiseFactor > 0) {
        EXPECT_LT(testing::noiseRoughness(out, s), c.noiseFactor * testing::noiseRoughness(s.depth, s))
            << c.setting << ", roughness " << roughness;
      }
    }
}

INSTANTIATE_TEST_SUITE_P(AllFilters, SurfaceFilterProperties, ::testing::ValuesIn(testing::surfaceFilterNameList()),
                         [](const auto& info) { return testing::filterTestName(info.param); });

TEST(SurfaceFilterOptions, UnknownNamesAndOutOfRangeValuesListTheValidOnes) {
  try {
    resolve({"gaussian"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--smoothing: unknown filter 'gaussian'; valid values: rof"),
              std::string::npos)
        << e.what();
  }
  try {
    resolve({"rof", 20000});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("--smoothing-iterations: 20000 is out of range for rof; valid values: 0..10000"),
        std::string::npos)
        << e.what();
  }
  try {
    resolve({"rof", -1, -3.0f});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--smoothing-strength: -3 is out of range for rof"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace flipscope
