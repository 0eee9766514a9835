// The factories of the filters behind createSurfaceFilter (smoothing/SurfaceFilter.cpp), one
// file each. Options arrive resolved (every default filled in, ranges checked) and with a
// strength and iterations above 0: without either, createSurfaceFilter copies the depth
// (makeNoFilter) instead.
#pragma once

#include <memory>

#include "smoothing/SurfaceFilter.h"

namespace flipscope::detail {

std::unique_ptr<SurfaceFilter> makeRofFilter(const SmoothingOptions& options);
std::unique_ptr<SurfaceFilter> makeBilateralFilter(const SmoothingOptions& options);
std::unique_ptr<SurfaceFilter> makeCurvatureFlowFilter(const SmoothingOptions& options);
std::unique_ptr<SurfaceFilter> makeNarrowRangeFilter(const SmoothingOptions& options);
std::unique_ptr<SurfaceFilter> makePlaneFitFilter(const SmoothingOptions& options);
std::unique_ptr<SurfaceFilter> makeNoFilter(const SmoothingOptions& options);

}  // namespace flipscope::detail
