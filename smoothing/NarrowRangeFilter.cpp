// `narrow-range`: the narrow-range filter of Truong and Yuksel 2018, "A Narrow-Range Filter for
// Screen-Space Fluid Rendering" (Proc. ACM Comput. Graph. Interact. Tech. 1(1)), the [TY18]
// filter that Oliveira and Paiva 2022 ("Narrow-Band Screen-Space Fluid Rendering", Sec. 2) sum up
// as smoothing "the foreground and background surface's depth values separately according to a
// narrow depth range using a Gaussian filter with adaptive kernel size" (kernels:
// smoothing/glsl/NarrowRange.glsl, which lists the rules: the depth range [z - delta, z + delta],
// samples in front of it ignored, samples behind it and the background clamped to z + mu, bias
// correction by mirror images, dynamic widening of the range).
//
// Oliveira and Paiva give no more than that summary and their settings ("a filter size of 7 x 7,
// and 4 iterations" at 1920 x 1080); the rest follows the authors' reference implementation
// (github.com/ttnghia/RealTimeFluidRendering, Shaders/filter-narrow-range.fs.glsl and its
// "1D + 2D" driver): delta = 10.5 r and mu = r (r the particle radius), sigma = R / 3 for a
// kernel radius R, and the separable approximation: each iteration but the last is a 1D pass
// along x and then one along y; the last is one 2D pass of a small radius, min(R, 4) pixels,
// which removes the axis-aligned artifacts of the separable passes. Departures from it: the
// Gaussian is lowered by its value at R (continuous in depth, so no pixel pops in or out of the
// support); the 2D pass walks outwards ring by ring, samples the axes too and weighs each sample
// by its distance in pixels (the reference's 2D pass skips the axes and scales the distance by
// the texel size twice, a box filter in effect); samples outside the image are ignored (with
// their mirror images) rather than repeating the border.
//
// Strength. --smoothing-strength s is the kernel radius in particle radii (world space): R =
// s * r * f / z pixels at depth z (f = focalPixels), at most kMaxRadius = 32 pixels (a 1D pass
// reads 2R + 1 pixels); s = 0 leaves the depth as it is. The default, 3, is the radius of the
// 7 x 7 window of Oliveira and Paiva where a particle radius spans one pixel. Iterations.
// --smoothing-iterations n: n - 1 separable iterations (x then y) and one final 2D pass; default
// 4 (Oliveira and Paiva, Sec. 5), at most 20; 0 leaves the depth as it is.
#include <cstddef>

#include "smoothing/detail/CpuScreenKernel.h"
#include "smoothing/detail/Filters.h"
#include "smoothing/detail/PassChain.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/NarrowRangeTypes.glsl"
static_assert(sizeof(NarrowRangeParams) == 32 && offsetof(NarrowRangeParams, maxRadius) == 4 &&
              offsetof(NarrowRangeParams, threshold) == 8 && offsetof(NarrowRangeParams, clampOffset) == 12 &&
              offsetof(NarrowRangeParams, axisX) == 16 && offsetof(NarrowRangeParams, axisY) == 20 &&
              offsetof(NarrowRangeParams, unused1) == 28);

struct NarrowRangeKernel : CpuScreenKernel {
  NarrowRangeParams S;
#include "smoothing/glsl/NarrowRange.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
using glsl::NarrowRangeKernel;
const ScreenPass kPass1D{"NarrowRange.comp", "narrowRange1D",
                         cpuScreenPass<NarrowRangeKernel, &NarrowRangeKernel::narrowRange1D>};
const ScreenPass kPass2D{"NarrowRange.comp", "narrowRange2D",
                         cpuScreenPass<NarrowRangeKernel, &NarrowRangeKernel::narrowRange2D>};

constexpr float kMaxRadius = 32.0f;       // pixels, the separable passes
constexpr float kMaxRadius2D = 4.0f;      // pixels, the final 2D pass (the reference's fixed radius)
constexpr float kThresholdRadii = 10.5f;  // delta in particle radii
constexpr float kClampRadii = 1.0f;       // mu in particle radii

class NarrowRangeFilter : public SurfaceFilter {
 public:
  explicit NarrowRangeFilter(const SmoothingOptions& options) : mOptions(options) {}

  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override {
    const float r = device.frame().particleRadius;
    glsl::NarrowRangeParams base{};
    base.worldRadius = mOptions.strength * r;
    base.maxRadius = kMaxRadius;
    base.threshold = kThresholdRadii * r;
    base.clampOffset = kClampRadii * r;
    glsl::NarrowRangeParams alongX = base, alongY = base, full = base;
    alongX.axisX = 1;
    alongY.axisY = 1;
    full.maxRadius = kMaxRadius2D;
    // n - 1 pairs of 1D passes (x, then y), then the 2D pass.
    const int passes = 2 * (mOptions.iterations - 1) + 1;
    mChain.run(device, depth, output, passes, [&](int i, ScreenImage from, ScreenImage to) {
      if (i + 1 == passes) {
        device.run(kPass2D, full, {from}, to);
      } else {
        device.run(kPass1D, i % 2 == 0 ? alongX : alongY, {from}, to);
      }
    });
  }

 private:
  SmoothingOptions mOptions;
  PassChain mChain;
};
}  // namespace

std::unique_ptr<SurfaceFilter> makeNarrowRangeFilter(const SmoothingOptions& options) {
  return std::make_unique<NarrowRangeFilter>(options);
}

}  // namespace detail
}  // namespace flipscope
