#include "smoothing/detail/CpuRofIterations.h"

#include <algorithm>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/Error.h"
#include "core/GlslShared.h"
#include "smoothing/ScreenTypes.h"

namespace flipscope {

namespace glsl {
/// Rof.glsl over two-channel images: ssLoad gives a pixel's (x, y) and z = w = 0, which is all
/// that rofDual and rofDivergence read of their inputs and write.
struct CompactRofKernel {
  ScreenFrame F{};
  RofParams S{};
  const vec2* images[3] = {};

  vec4 ssLoad(uint image, ivec2 p) const {
    const ivec2 q = clamp(p, ivec2(0), ivec2(int(F.size.x) - 1, int(F.size.y) - 1));
    const vec2 v = images[image][uint(q.y) * F.size.x + uint(q.x)];
    return vec4(v.x, v.y, 0.0f, 0.0f);
  }
#include "smoothing/glsl/ScreenMath.glsl"
#include "smoothing/glsl/Rof.glsl"
};
}  // namespace glsl

namespace detail {
namespace {

/// A run of domain pixels [begin, end) of one row.
struct Run {
  std::uint32_t begin, end;
};

constexpr std::uint32_t kBandRows = 16;  ///< rows of the bands a thread iterates in turn

}  // namespace

void iterateRofOnCpu(CpuScreenDevice& device, const glsl::RofParams& params, int iterations, ScreenImage domain,
                     ScreenImage div) {
  const ScreenFrame& frame = device.frame();
  const std::uint32_t width = frame.size.x, height = frame.size.y;
  const std::size_t n = std::size_t(width) * height;
  const auto domainPixels = device.pixels(domain);
  FLIPSCOPE_CHECK(domainPixels.size() == n);
  // The domain (depth, mask) and its runs per row; p^(0) = 0 and (div p^(0), lambda^(0)) as
  // rofStart gives them.
  std::vector<glm::vec2> compactDomain(n), dual[2], divergence[2];
  dual[0].assign(n, glm::vec2(0.0f));
  dual[1].assign(n, glm::vec2(0.0f));
  divergence[0].resize(n);
  divergence[1].assign(n, glm::vec2(0.0f));
  std::vector<Run> runs;
  std::vector<std::size_t> rowRuns(height + 1, 0);  // row y's runs: [rowRuns[y], rowRuns[y + 1])
  for (std::uint32_t y = 0; y < height; ++y) {
    rowRuns[y] = runs.size();
    for (std::uint32_t x = 0; x < width; ++x) {
      const glm::vec4& d = domainPixels[std::size_t(y) * width + x];
      compactDomain[std::size_t(y) * width + x] = glm::vec2(d.x, d.y);
      divergence[0][std::size_t(y) * width + x] = glm::vec2(0.0f, d.z);
      if (d.y < 0.5f) continue;  // as the kernels: outside the domain
      if (runs.size() == rowRuns[y] || runs.back().end != x) runs.push_back({x, x});
      ++runs.back().end;
    }
  }
  rowRuns[height] = runs.size();
  // kernel(p) at every domain pixel p of row y, into `out` (its x and y: z = w = 0).
  auto row = [&](std::vector<glm::vec2>& out, std::uint32_t y, auto kernel) {
    for (std::size_t r = rowRuns[y]; r < rowRuns[y + 1]; ++r) {
      for (std::uint32_t x = runs[r].begin; x < runs[r].end; ++x) {
        const glm::vec4 v = kernel(glm::ivec2(int(x), int(y)));
        out[std::size_t(y) * width + x] = glm::vec2(v.x, v.y);
      }
    }
  };
  // One iteration is one sweep: a band's rows get p^(n+1) (rofDual: rows y and y + 1 of the
  // last iteration) and right after it div p^(n+1) (rofDivergence: rows y and y - 1 of p^(n+1)),
  // while both are in the caches. The first row of a band needs the band above: it comes last.
  const std::uint32_t bands = (height + kBandRows - 1) / kBandRows;
  int current = 0;
  for (int i = 0; i < iterations; ++i) {
    const int next = 1 - current;
    glsl::CompactRofKernel dualKernel, divKernel;
    dualKernel.F = divKernel.F = frame;
    dualKernel.S = divKernel.S = params;
    dualKernel.images[0] = divKernel.images[0] = compactDomain.data();
    dualKernel.images[1] = dual[current].data();
    divKernel.images[1] = dual[next].data();
    dualKernel.images[2] = divKernel.images[2] = divergence[current].data();
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, bands, 1),
        [&](const tbb::blocked_range<std::uint32_t>& range) {
          glsl::CompactRofKernel duals = dualKernel, divs = divKernel;
          for (std::uint32_t b = range.begin(); b != range.end(); ++b) {
            const std::uint32_t first = b * kBandRows, last = std::min(height, first + kBandRows);
            for (std::uint32_t y = first; y < last; ++y) {
              row(dual[next], y, [&](glm::ivec2 p) { return duals.rofDual(p); });
              if (y > first || b == 0) row(divergence[next], y, [&](glm::ivec2 p) { return divs.rofDivergence(p); });
            }
          }
        },
        tbb::simple_partitioner());
    tbb::parallel_for(std::uint32_t(1), bands, [&](std::uint32_t b) {
      glsl::CompactRofKernel divs = divKernel;
      row(divergence[next], b * kBandRows, [&](glm::ivec2 p) { return divs.rofDivergence(p); });
    });
    current = next;
  }
  const auto out = device.pixels(div);
  FLIPSCOPE_CHECK(out.size() == n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      out[i] = glm::vec4(divergence[current][i].x, divergence[current][i].y, 0.0f, 0.0f);
  });
}

}  // namespace detail
}  // namespace flipscope
