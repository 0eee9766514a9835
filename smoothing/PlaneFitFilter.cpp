// `plane-fit`: iterative local plane fitting by moving least squares, Imai, Kanamori, Mitani 2016,
// "Real-time screen-space liquid rendering with complex refractions" (up to four refractions;
// Sec. 4.3; kernels: smoothing/glsl/PlaneFit.glsl). Per iteration and pixel: a plane fitted to
// the eye-space positions of the foreground pixels of a window (eq. 1), weighted by
// exp(-(z_i - z_j)^2 / sigma^2) with sigma = 5.3 particle radii as in the paper (eq. 2), its
// normal the weighted mean of the input's normals (eq. 3; the paper's particle normals are
// reconstructed here once from the input depth by one-sided differences), its offset from
// dE/dd = 0 (eq. 4); the pixel's depth becomes that of its view ray's intersection with the
// plane (eq. 5), moved by at most the window's radius in world units (a plane seen nearly
// edge-on would move it arbitrarily far).
//
// Strength. --smoothing-strength k is the window radius in particle radii: a disk of k r world
// units at the pixel's depth, k r f / z pixels (f the focal length in pixels), at most
// kMaxRadiusPixels = 8 pixels (a 17 x 17 window, about 3.5 times the paper's 9 x 9, which
// bounds the cost when particles are large on screen); 0 leaves the depth unchanged. The
// default 2 (one particle diameter) is the paper's 9 x 9 window for particles of about 2 pixels'
// radius. Larger windows smooth more but, as any plane fit, flatten curved surfaces: a convex
// one of curvature radius R moves back by about (k r)^2 / (4 R) per iteration, by more where
// the view ray grazes it.
//
// Iterations. --smoothing-iterations is the number of fits; the default 2 is the paper's
// "wave" scene (its "steps" and million-particle scenes use 5).
#include <cstddef>
#include <optional>

#include "smoothing/detail/CpuScreenKernel.h"
#include "smoothing/detail/Filters.h"
#include "smoothing/detail/PassChain.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/PlaneFitTypes.glsl"
static_assert(sizeof(PlaneFitParams) == 16 && offsetof(PlaneFitParams, maxRadius) == 4 &&
              offsetof(PlaneFitParams, invSigma2) == 8 && offsetof(PlaneFitParams, moveLimit) == 12);

struct PlaneFitKernel : CpuScreenKernel {
  PlaneFitParams S;
#include "smoothing/glsl/PlaneFit.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
using glsl::PlaneFitKernel;
const ScreenPass kNormals{"PlaneFit.comp", "pfNormals", cpuScreenPass<PlaneFitKernel, &PlaneFitKernel::pfNormals>};
const ScreenPass kFit{"PlaneFit.comp", "pfFit", cpuScreenPass<PlaneFitKernel, &PlaneFitKernel::pfFit>};

constexpr float kMaxRadiusPixels = 8.0f;
constexpr float kSigmaRadii = 5.3f;  ///< the paper's sigma of the depth weight, in particle radii

class PlaneFitFilter : public SurfaceFilter {
 public:
  explicit PlaneFitFilter(const SmoothingOptions& options) : mOptions(options) {}

  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override {
    if (!mNormals) mNormals = device.createFrameImage();
    const ScreenFrame& frame = device.frame();
    const float r = frame.particleRadius;
    const float sigma = kSigmaRadii * r;
    glsl::PlaneFitParams params{};
    params.worldRadius = mOptions.strength * r;
    params.maxRadius = kMaxRadiusPixels;
    params.invSigma2 = 1.0f / (sigma * sigma);
    params.moveLimit = 1.0f;
    device.run(kNormals, params, {depth}, *mNormals);
    mChain.run(device, depth, output, mOptions.iterations, [&](int, ScreenImage from, ScreenImage to) {
      device.run(kFit, params, {from, *mNormals}, to);
    });
  }

 private:
  SmoothingOptions mOptions;
  std::optional<ScreenImage> mNormals;
  PassChain mChain;
};
}  // namespace

std::unique_ptr<SurfaceFilter> makePlaneFitFilter(const SmoothingOptions& options) {
  return std::make_unique<PlaneFitFilter>(options);
}

}  // namespace detail
}  // namespace flipscope
