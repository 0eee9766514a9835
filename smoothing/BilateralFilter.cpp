// `bilateral`: a depth-adaptive bilateral filter of the depth image, the bilateral Gaussian
// (Tomasi and Manduchi 1998) that screen-space fluid rendering smooths its depth with (Green
// 2010, "Screen Space Fluid Rendering for Games", GDC; the [Gre10] filter of Oliveira and Paiva
// 2022), with a kernel of constant world-space size (kernel: smoothing/glsl/Bilateral.glsl).
//
// At a pixel of depth z the kernel radius is R = s * r * f / z pixels (s = strength, r the
// particle radius in world units, f = focalPixels), at most kMaxRadius = 24 pixels (a 49 x 49
// window; beyond it a pass costs too much, and the kernel stops growing towards the eye). The
// spatial weight is a Gaussian of sigma = R / 2, minus its value at R (so it falls continuously
// to 0 there). The range weight is a Gaussian of the depth difference whose sigma is the spatial
// one in world units, sigma_z = (R / 2) * z / f = s * r / 2 (2 r at the default strength): below
// the radius bound the kernel is an isotropic Gaussian in eye space. A sigma_z fixed at 2 r whatever the strength
// makes a wide kernel on a sloped surface keep the pixel's own noise (the depths across the
// kernel spread far beyond sigma_z, so only samples as rough as the pixel count) and a larger
// strength then roughens the sphere of the tests instead of smoothing it. Depth steps between
// surfaces many particle radii apart still get no weight (25 r is over 3 sigma_z up to s = 16).
// Only foreground samples contribute; background pixels keep their input.
//
// Strength. --smoothing-strength s is the kernel radius in particle radii (world space): the
// same surface is smoothed alike at any distance, zoom or image size. 0 leaves the depth as it
// is. Iterations. --smoothing-iterations n applies the filter n times (default 1, at most 10);
// 0 leaves the depth as it is.
#include <cstddef>

#include "smoothing/detail/CpuScreenKernel.h"
#include "smoothing/detail/Filters.h"
#include "smoothing/detail/PassChain.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/BilateralTypes.glsl"
static_assert(sizeof(BilateralParams) == 16 && offsetof(BilateralParams, maxRadius) == 4 &&
              offsetof(BilateralParams, sigmaDepth) == 8 && offsetof(BilateralParams, unused0) == 12);

struct BilateralKernel : CpuScreenKernel {
  BilateralParams S;
#include "smoothing/glsl/Bilateral.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
using glsl::BilateralKernel;
const ScreenPass kBilateral{"Bilateral.comp", "bilateral", cpuScreenPass<BilateralKernel, &BilateralKernel::bilateral>};

constexpr float kMaxRadius = 24.0f;  // pixels

class BilateralFilter : public SurfaceFilter {
 public:
  explicit BilateralFilter(const SmoothingOptions& options) : mOptions(options) {}

  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override {
    const float r = device.frame().particleRadius;
    glsl::BilateralParams params{};
    params.worldRadius = mOptions.strength * r;
    params.maxRadius = kMaxRadius;
    params.sigmaDepth = 0.5f * mOptions.strength * r;  // the spatial sigma, R / 2, in world units
    mChain.run(device, depth, output, mOptions.iterations,
               [&](int, ScreenImage from, ScreenImage to) { device.run(kBilateral, params, {from}, to); });
  }

 private:
  SmoothingOptions mOptions;
  PassChain mChain;
};
}  // namespace

std::unique_ptr<SurfaceFilter> makeBilateralFilter(const SmoothingOptions& options) {
  return std::make_unique<BilateralFilter>(options);
}

}  // namespace detail
}  // namespace flipscope
