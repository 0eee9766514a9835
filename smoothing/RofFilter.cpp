// `rof`, the default filter: adaptive ROF smoothing by Chambolle's projection, exactly as Reichl
// et al. 2014 §3.4 give it (kernels: smoothing/glsl/Rof.glsl). tau = 0.25; p and div p start at
// 0, lambda at lambda^(0) of eq. 7; the depth is extruded by one pixel first; then per iteration
// one dual update (eq. 2, forward differences) and one divergence and lambda update (backward
// differences, eq. 7); finally u = v - lambda div p on the foreground (eq. 3).
//
// Strength. --smoothing-strength k sets lambda0 = k * f * r^2, with f the focal length in pixels
// and r the particle radius in world units. ROF lowers a bump of radius R pixels by about
// 2 lambda / R (world units), and a particle-sized bump at depth z spans R = f r / z pixels, so
// with lambda_ij = lambda0 / z_ij (eq. 7) it is lowered by about 2 k r at any distance, zoom or
// image size: k is a strength in particle radii, independent of the scene's scale. That is the
// converged result; 75 iterations (the paper's) smooth features up to about 6 pixels across,
// so on particles much larger than that on screen more iterations smooth further.
// epsilon = r (world units) keeps lambda finite at the eye. k = 0 (lambda = 0, which eq. 2 divides
// by) leaves the depth as it is: createSurfaceFilter copies it.
#include <cstddef>
#include <optional>

#include "smoothing/detail/CpuRofIterations.h"
#include "smoothing/detail/CpuScreenKernel.h"
#include "smoothing/detail/Filters.h"

namespace flipscope {

namespace glsl {
static_assert(sizeof(RofParams) == 16 && offsetof(RofParams, adaptive) == 12);

struct RofKernel : CpuScreenKernel {
  RofParams S;
#include "smoothing/glsl/Rof.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
using glsl::RofKernel;
const ScreenPass kExtrude{"Rof.comp", "rofExtrude", cpuScreenPass<RofKernel, &RofKernel::rofExtrude>};
const ScreenPass kStart{"Rof.comp", "rofStart", cpuScreenPass<RofKernel, &RofKernel::rofStart>};
const ScreenPass kDual{"Rof.comp", "rofDual", cpuScreenPass<RofKernel, &RofKernel::rofDual>};
const ScreenPass kDivergence{"Rof.comp", "rofDivergence", cpuScreenPass<RofKernel, &RofKernel::rofDivergence>};
const ScreenPass kResult{"Rof.comp", "rofResult", cpuScreenPass<RofKernel, &RofKernel::rofResult>};

class RofFilter : public SurfaceFilter {
 public:
  explicit RofFilter(const SmoothingOptions& options) : mOptions(options) {}

  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override {
    // The CPU device iterates over compact images of its own (detail/CpuRofIterations.h), with
    // the same result; it needs no dual images, nor a second div.
    auto* cpu = dynamic_cast<CpuScreenDevice*>(&device);
    if (!mDomain) {
      mDomain = device.createFrameImage();
      mDiv[0] = device.createFrameImage();
      if (!cpu) {
        for (ScreenImage& image : mDual) image = device.createFrameImage();
        mDiv[1] = device.createFrameImage();
      }
    }
    const ScreenFrame& frame = device.frame();
    const float r = frame.particleRadius;
    glsl::RofParams params{};
    params.lambda0 = mOptions.strength * frame.focalPixels * r * r;
    params.epsilon = r;
    params.tau = 0.25f;
    params.adaptive = mOptions.strength > 0 ? 1u : 0u;
    device.run(kExtrude, params, {depth}, *mDomain);
    if (cpu) {
      mCpuIterations.run(*cpu, params, mOptions.iterations, *mDomain, mDiv[0]);
      device.run(kResult, params, {depth, mDiv[0]}, output);
      return;
    }
    device.run(kStart, params, {*mDomain}, mDiv[0]);
    device.clear(mDual[0]);  // p^(0) = 0
    int current = 0;
    for (int i = 0; i < mOptions.iterations; ++i) {
      device.run(kDual, params, {*mDomain, mDual[current], mDiv[current]}, mDual[1 - current]);
      device.run(kDivergence, params, {*mDomain, mDual[1 - current], mDiv[current]}, mDiv[1 - current]);
      current = 1 - current;
    }
    device.run(kResult, params, {depth, mDiv[current]}, output);
  }

 private:
  SmoothingOptions mOptions;
  std::optional<ScreenImage> mDomain;
  CpuRofIterations mCpuIterations;
  ScreenImage mDual[2] = {}, mDiv[2] = {};
};
}  // namespace

std::unique_ptr<SurfaceFilter> makeRofFilter(const SmoothingOptions& options) {
  return std::make_unique<RofFilter>(options);
}

}  // namespace detail
}  // namespace flipscope
