// The iterations of the ROF filter (smoothing/RofFilter.cpp, Reichl et al. 2014 §3.4) on the
// CPU device, over compact images: the same kernels (rofDual, rofDivergence of Rof.glsl), the
// same arithmetic and so the same result, bit for bit, as the passes run one by one over the
// device's vec4 images. Only the two channels each iterated image holds are stored (dual: p;
// div: div p and lambda), and only the pixels of the filter's domain are visited: the others
// stay 0, as the kernels return there. Each iteration then moves a third of the bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "smoothing/CpuScreenDevice.h"

namespace flipscope::glsl {
#include "smoothing/glsl/RofTypes.glsl"
}  // namespace flipscope::glsl

namespace flipscope::detail {

/// The compact images, kept from frame to frame (a filter owns one).
class CpuRofIterations {
 public:
  /// Runs `iterations` ROF iterations from p = 0 and the domain's lambda^(0) (rofStart), on
  /// `domain` (rofExtrude's image); writes div p and lambda of the last one to `div` as
  /// rofDivergence writes them (div p^(0) and lambda^(0) when `iterations` is 0).
  void run(CpuScreenDevice& device, const glsl::RofParams& params, int iterations, ScreenImage domain,
           ScreenImage div);

 private:
  /// A run of domain pixels [begin, end) of one row.
  struct Run {
    std::uint32_t begin, end;
  };
  std::vector<glm::vec2> mDomain, mDual[2], mDivergence[2];  ///< (depth, mask); p; (div p, lambda)
  std::vector<Run> mRuns;
  std::vector<std::size_t> mRowRuns;  ///< row y's runs: mRuns[mRowRuns[y], mRowRuns[y + 1])
};

}  // namespace flipscope::detail
