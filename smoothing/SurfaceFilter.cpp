// The filter registry: names, defaults and ranges of `--smoothing`, and the factories
// (smoothing/detail/Filters.h). Adding a filter: one file with its factory, one row here.
#include "smoothing/SurfaceFilter.h"

#include <cmath>
#include <functional>

#include "core/Error.h"
#include "core/NumberText.h"
#include "smoothing/detail/Filters.h"

namespace flipscope {

namespace {
struct Entry {
  SurfaceFilterInfo info;
  std::function<std::unique_ptr<SurfaceFilter>(const SmoothingOptions&)> make;
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = {
      {{"rof", "adaptive ROF total-variation smoothing, Chambolle's projection (Reichl et al. 2014 Sec. 3.4)",
        "k in lambda0 = k * focal length * radius^2 (eq. 7): larger smooths more, at any scale or zoom", 75, 10000, 8.0f,
        0.0f, 1000.0f},
       detail::makeRofFilter},
      {{"bilateral", "depth-adaptive bilateral Gaussian with a world-space kernel (Green 2010, GDC)",
        "kernel radius in particle radii (sigma = radius / 2 across and in depth; at most 24 px)", 1, 10, 4.0f, 0.0f,
        16.0f},
       detail::makeBilateralFilter},
      {{"narrow-range", "narrow-range filter: separable passes and a final 2D pass (Truong and Yuksel 2018)",
        "kernel radius in particle radii (sigma = radius / 3, at most 32 px)", 4, 20, 3.0f, 0.0f, 16.0f},
       detail::makeNarrowRangeFilter},
      {{"curvature-flow", "screen-space curvature flow, explicit Euler steps of dz/dt = H (van der Laan et al. 2009)",
        "time step as a fraction of the explicit stability limit z*Cx*Cy/(Cx+Cy): blur ~ sqrt(s*steps/2) px", 60,
        1000, 0.5f, 0.0f, 1.0f},
       detail::makeCurvatureFlowFilter},
      {{"plane-fit", "iterative MLS plane fitting in eye space (Imai, Kanamori, Mitani 2016, Sec. 4.3)",
        "window radius in particle radii (at most 8 px; depth weight sigma = 5.3 radii)", 2, 50, 2.0f, 0.0f, 50.0f},
       detail::makePlaneFitFilter},
      {{"none", "no smoothing: the sphere depth as the ray-caster wrote it", "unused", 0, 0, 0.0f, 0.0f, 0.0f},
       detail::makeNoFilter},
  };
  return table;
}

const Entry* find(const std::string& name) {
  for (const Entry& entry : entries())
    if (entry.info.name == name) return &entry;
  return nullptr;
}

}  // namespace

const std::vector<SurfaceFilterInfo>& surfaceFilters() {
  static const std::vector<SurfaceFilterInfo> infos = [] {
    std::vector<SurfaceFilterInfo> list;
    for (const Entry& entry : entries()) list.push_back(entry.info);
    return list;
  }();
  return infos;
}

std::string surfaceFilterNames() {
  std::string names;
  for (const Entry& entry : entries()) names += (names.empty() ? "" : ", ") + std::string(entry.info.name);
  return names;
}

SmoothingOptions resolve(const SmoothingOptions& options) {
  const Entry* entry = find(options.name);
  if (!entry)
    throw InputError("--smoothing: unknown filter '" + options.name + "'; valid values: " + surfaceFilterNames());
  const SurfaceFilterInfo& info = entry->info;
  SmoothingOptions out = options;
  if (out.iterations == -1) out.iterations = info.defaultIterations;
  if (out.iterations < 0 || out.iterations > info.maxIterations)
    throw InputError("--smoothing-iterations: " + std::to_string(out.iterations) + " is out of range for " +
                     std::string(info.name) + "; valid values: " +
                     (info.maxIterations == 0 ? std::string("0 (the filter has no iterations)")
                                              : "0.." + std::to_string(info.maxIterations)));
  if (out.strength == -1.0f) out.strength = info.defaultStrength;
  if (!std::isfinite(out.strength) || out.strength < info.minStrength || out.strength > info.maxStrength)
    throw InputError("--smoothing-strength: " + numberText(out.strength) + " is out of range for " +
                     std::string(info.name) + " (" + std::string(info.strengthMeaning) +
                     "); valid values: " + numberText(info.minStrength) + ".." + numberText(info.maxStrength));
  return out;
}

std::unique_ptr<SurfaceFilter> createSurfaceFilter(const SmoothingOptions& options) {
  const SmoothingOptions resolved = resolve(options);
  // No strength or no iterations: every filter leaves the depth as it is.
  if (resolved.strength == 0.0f || resolved.iterations == 0) return detail::makeNoFilter(resolved);
  return find(resolved.name)->make(resolved);
}

namespace detail {
namespace {
class NoFilter : public SurfaceFilter {
 public:
  void apply(ScreenDevice& device, ScreenImage depth, ScreenImage output) override { device.copy(depth, output); }
  bool keepsDepth() const override { return true; }
};
}  // namespace

std::unique_ptr<SurfaceFilter> makeNoFilter(const SmoothingOptions&) { return std::make_unique<NoFilter>(); }
}  // namespace detail

}  // namespace flipscope
