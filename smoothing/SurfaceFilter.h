// Screen-space surface smoothing (Reichl et al. 2014 §3.4, §4.5): a filter turns the sphere depth
// image of the ray-caster into a smooth liquid surface. Every filter runs as passes on a
// ScreenDevice, so one implementation serves the GPU and its CPU reference.
//
//   auto filter = createSurfaceFilter({.name = "rof"});
//   filter->apply(device, depthImage, smoothedImage);
//
// Depth images: x = linear camera depth in world units, y = foreground mask (1 where a ray hit a
// sphere, 0 elsewhere); z, w are ignored on input. The output holds the smoothed depth in x and
// the unchanged mask in y; background pixels keep their input depth (never written).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "smoothing/ScreenDevice.h"

namespace flipscope {

struct SmoothingOptions {
  std::string name = "rof";  ///< a name of surfaceFilters()
  int iterations = -1;       ///< -1: the filter's default
  float strength = -1.0f;    ///< -1: the filter's default; its meaning is the filter's
};

class SurfaceFilter {
 public:
  virtual ~SurfaceFilter() = default;
  /// Smooths `depth` into `output` (both frame images on `device`, output not depth).
  virtual void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) = 0;
  /// Whether apply() leaves the depth as it is (a copy), so that a caller may read `depth`
  /// itself and not run it.
  virtual bool keepsDepth() const { return false; }
};

/// What `--smoothing NAME` offers, with defaults and the range of each parameter.
struct SurfaceFilterInfo {
  std::string_view name;
  std::string_view summary;        ///< one line, with the paper it implements
  std::string_view strengthMeaning;  ///< what --smoothing-strength sets
  int defaultIterations;
  int maxIterations;               ///< 0: the filter takes no iterations
  float defaultStrength;
  float minStrength, maxStrength;  ///< inclusive
};
const std::vector<SurfaceFilterInfo>& surfaceFilters();
/// "rof, bilateral, curvature-flow, narrow-range, plane-fit, none".
std::string surfaceFilterNames();

/// The options with every default filled in. Throws InputError naming the option
/// (--smoothing, --smoothing-iterations, --smoothing-strength) and listing the valid values.
SmoothingOptions resolve(const SmoothingOptions& options);
/// The filter (options are resolved first; at strength 0 or 0 iterations, a copy of the depth).
/// Throws InputError as resolve() does.
std::unique_ptr<SurfaceFilter> createSurfaceFilter(const SmoothingOptions& options);

}  // namespace flipscope
