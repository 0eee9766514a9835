// `curvature-flow`: screen-space curvature flow, van der Laan, Green, Sainz 2009, "Screen Space
// Fluid Rendering with Curvature Flow" (I3D 2009; thesis chapter 5, Sec. 5.3.2; kernels:
// smoothing/glsl/CurvatureFlow.glsl). The depth image evolves by explicit Euler steps of
// dz/dt = H (eq. 5.1), H the mean curvature of the depth surface (eq. 5.6) with the paper's
// Cx = 2 / (Vx Fx), Cy = 2 / (Vy Fy), D and Ex, Ey (eq. 5.4-5.8; the Wx, Wy terms neglected as
// the paper does), H taken for the normal towards the eye so that bumps flatten. Derivatives
// are central differences; across the screen edge, the background and large depth jumps they
// are forced to 0 (Sec. 5.3.2), with the jumps found once on the input: a neighbour is across
// one when the depths differ by more than 4 particle radii plus 2 pixel footprints (z Cx) of
// slope.
//
// Iterations. --smoothing-iterations is the number of time steps; the default 60 is the
// largest count of the paper's Fig. 5.7 (40 and 60 steps).
//
// Strength. --smoothing-strength s is the time step as a fraction of the explicit Euler
// stability limit of a flat surface at the pixel's depth: dt = s z Cx Cy / (Cx + Cy) world
// units (z the pixel's depth; about z / (2 f), f the focal length in pixels). Dimensionless,
// 0..1 (1: the limit; 0: no change). One step then moves a nearly flat surface by
// s/4 of its 5-point pixel Laplacian, so N steps blur like a Gaussian of sigma ~ sqrt(s N / 2)
// pixels, at any depth: like the paper's fixed step, the smoothing is a screen-space length
// (more steps at higher resolutions). The default 0.5 keeps half the limit as a margin for
// the steep, nonlinear parts of the flow and, with 60 steps, blurs by about 4 pixels.
#include <algorithm>
#include <cstddef>
#include <optional>

#include "smoothing/detail/CpuScreenKernel.h"
#include "smoothing/detail/Filters.h"
#include "smoothing/detail/PassChain.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/CurvatureFlowTypes.glsl"
static_assert(sizeof(CurvatureFlowParams) == 32 && offsetof(CurvatureFlowParams, stepPerDepth) == 8 &&
              offsetof(CurvatureFlowParams, jumpBase) == 12 && offsetof(CurvatureFlowParams, jumpPerDepth) == 16 &&
              offsetof(CurvatureFlowParams, unused2) == 28);

struct CurvatureFlowKernel : CpuScreenKernel {
  CurvatureFlowParams S;
#include "smoothing/glsl/CurvatureFlow.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
using glsl::CurvatureFlowKernel;
const ScreenPass kLinks{"CurvatureFlow.comp", "cfLinks",
                        cpuScreenPass<CurvatureFlowKernel, &CurvatureFlowKernel::cfLinks>};
const ScreenPass kStep{"CurvatureFlow.comp", "cfStep",
                       cpuScreenPass<CurvatureFlowKernel, &CurvatureFlowKernel::cfStep>};

constexpr float kJumpRadii = 4.0f;       ///< depth jump, in particle radii, that is a discontinuity
constexpr float kJumpFootprints = 2.0f;  ///< plus this many pixel footprints (a slope of ~63 degrees)

class CurvatureFlowFilter : public SurfaceFilter {
 public:
  explicit CurvatureFlowFilter(const SmoothingOptions& options) : mOptions(options) {}

  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override {
    if (!mLinks) mLinks = device.createFrameImage();
    const ScreenFrame& frame = device.frame();
    glsl::CurvatureFlowParams params{};
    params.cx = 2.0f * frame.tanHalfFovY * frame.aspect / float(frame.width);
    params.cy = 2.0f * frame.tanHalfFovY / float(frame.height);
    params.stepPerDepth = mOptions.strength * params.cx * params.cy / (params.cx + params.cy);
    params.jumpBase = kJumpRadii * frame.particleRadius;
    params.jumpPerDepth = kJumpFootprints * std::max(params.cx, params.cy);
    device.run(kLinks, params, {depth}, *mLinks);
    mChain.run(device, depth, output, mOptions.iterations, [&](int, ScreenImage from, ScreenImage to) {
      device.run(kStep, params, {from, *mLinks}, to);
    });
  }

 private:
  SmoothingOptions mOptions;
  std::optional<ScreenImage> mLinks;
  PassChain mChain;
};
}  // namespace

std::unique_ptr<SurfaceFilter> makeCurvatureFlowFilter(const SmoothingOptions& options) {
  return std::make_unique<CurvatureFlowFilter>(options);
}

}  // namespace detail
}  // namespace flipscope
