#include "smoothing/detail/CpuRofIterations.h"

#include <algorithm>

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
    const ivec2 q = clamp(p, ivec2(0), ivec2(int(F.width) - 1, int(F.height) - 1));
    const vec2 v = images[image][uint(q.y) * F.width + uint(q.x)];
    return vec4(v.x, v.y, 0.0f, 0.0f);
  }
#include "smoothing/glsl/ScreenMath.glsl"
#include "smoothing/glsl/Rof.glsl"
};
}  // namespace glsl

namespace detail {
namespace {
constexpr std::uint32_t kBandRows = 16;  ///< rows of the bands a thread iterates in turn
}  // namespace

void CpuRofIterations::run(CpuScreenDevice& device, const glsl::RofParams& params, int iterations,
                           ScreenImage domain, ScreenImage div) {
  const ScreenFrame& frame = device.frame();
  const std::uint32_t width = frame.width, height = frame.height;
  const std::size_t n = std::size_t(width) * height;
  const auto domainPixels = device.pixels(domain);
  FLIPSCOPE_CHECK(domainPixels.size() == n);
  // The domain (depth, mask) and its runs per row; p^(0) = 0 and (div p^(0), lambda^(0)) as
  // rofStart gives them. The pixels outside the domain stay 0 in every image.
  mDomain.resize(n);
  mDual[0].assign(n, glm::vec2(0.0f));
  mDual[1].assign(n, glm::vec2(0.0f));
  mDivergence[0].resize(n);
  mDivergence[1].assign(n, glm::vec2(0.0f));
  mRuns.clear();
  mRowRuns.assign(height + 1, 0);
  for (std::uint32_t y = 0; y < height; ++y) {
    mRowRuns[y] = mRuns.size();
    for (std::uint32_t x = 0; x < width; ++x) {
      const glm::vec4& d = domainPixels[std::size_t(y) * width + x];
      mDomain[std::size_t(y) * width + x] = glm::vec2(d.x, d.y);
      mDivergence[0][std::size_t(y) * width + x] = glm::vec2(0.0f, d.z);
      if (d.y < 0.5f) continue;  // as the kernels: outside the domain
      if (mRuns.size() == mRowRuns[y] || mRuns.back().end != x) mRuns.push_back({x, x});
      ++mRuns.back().end;
    }
  }
  mRowRuns[height] = mRuns.size();
  // kernel(p) at every domain pixel p of row y, into `out` (its x and y: z = w = 0).
  auto row = [&](std::vector<glm::vec2>& out, std::uint32_t y, auto kernel) {
    for (std::size_t r = mRowRuns[y]; r < mRowRuns[y + 1]; ++r) {
      for (std::uint32_t x = mRuns[r].begin; x < mRuns[r].end; ++x) {
        const glm::vec4 v = kernel(glm::ivec2(int(x), int(y)));
        out[std::size_t(y) * width + x] = glm::vec2(v.x, v.y);
      }
    }
  };
  // One iteration is one sweep: a band's rows get p^(n+1) (rofDual: rows y and y + 1 of the
  // last iteration) and right after it div p^(n+1) (rofDivergence: rows y and y - 1 of p^(n+1)),
  // while both are in the caches. The first row of a band needs the band above: it comes last.
  const std::uint32_t bands = (height + kBandRows - 1) / kBandRows;
  glsl::CompactRofKernel dualKernel, divKernel;
  dualKernel.F = divKernel.F = frame;
  dualKernel.S = divKernel.S = params;
  dualKernel.images[0] = divKernel.images[0] = mDomain.data();
  int current = 0;
  for (int i = 0; i < iterations; ++i) {
    const int next = 1 - current;
    dualKernel.images[1] = mDual[current].data();
    divKernel.images[1] = mDual[next].data();
    dualKernel.images[2] = divKernel.images[2] = mDivergence[current].data();
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, bands, 1),
        [&](const tbb::blocked_range<std::uint32_t>& range) {
          glsl::CompactRofKernel duals = dualKernel, divs = divKernel;
          for (std::uint32_t b = range.begin(); b != range.end(); ++b) {
            const std::uint32_t first = b * kBandRows, last = std::min(height, first + kBandRows);
            for (std::uint32_t y = first; y < last; ++y) {
              row(mDual[next], y, [&](glm::ivec2 p) { return duals.rofDual(p); });
              if (y > first || b == 0) row(mDivergence[next], y, [&](glm::ivec2 p) { return divs.rofDivergence(p); });
            }
          }
        },
        tbb::simple_partitioner());
    tbb::parallel_for(std::uint32_t(1), bands, [&](std::uint32_t b) {
      glsl::CompactRofKernel divs = divKernel;
      row(mDivergence[next], b * kBandRows, [&](glm::ivec2 p) { return divs.rofDivergence(p); });
    });
    current = next;
  }
  const auto out = device.pixels(div);
  FLIPSCOPE_CHECK(out.size() == n);
  const std::vector<glm::vec2>& last = mDivergence[current];
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) out[i] = glm::vec4(last[i].x, last[i].y, 0.0f, 0.0f);
  });
}

}  // namespace detail
}  // namespace flipscope
