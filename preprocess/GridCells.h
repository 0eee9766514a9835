// GridCells: the cell of the binning grid that holds a particle, four particles at a time. A
// particle's cell is floor((double(p) - origin) * inverseCellSize), in double precision so the
// store does not depend on the float rounding of the grid's far side (computeKeys,
// BrickBinning.cpp; Reichl et al. 2014 §3.1 bin particles into the cells of a uniform grid). On
// x86-64-v2 builds (the default) four particles are converted, floored and bounds-checked in SSE
// registers, two doubles a register, with the same IEEE operations as the scalar form, so the
// cells are the same bit for bit; elsewhere the scalar form runs four times. The convert spent
// a third of its time on this arithmetic one particle at a time (2026-12-07, the 100 M raw
// frame of bench preprocess).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include <glm/vec3.hpp>

#include "core/Box.h"
#include "core/Error.h"
#include "core/FastFloor.h"

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace flipscope::detail {

/// The cells of four particles, an array an axis.
struct CellsOfFour {
  alignas(16) std::uint32_t x[4];
  alignas(16) std::uint32_t y[4];
  alignas(16) std::uint32_t z[4];
};

class GridCells {
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();

 public:
  /// A grid of `cells` cells along each axis (each below 2^31), from `origin`, cells of
  /// 1 / `inverseCellSize`; where `clip` is given, a particle outside it is outside the grid.
  GridCells(const glm::dvec3& origin, double inverseCellSize, const glm::u64vec3& cells,
            const std::optional<Box>& clip = std::nullopt)
      : mOrigin(origin),
        mInverse(inverseCellSize),
        mLimit(cells),
        mClip(clip.value_or(Box{glm::dvec3(-kInfinity), glm::dvec3(kInfinity)})) {
    FLIPSCOPE_CHECK(cells.x >= 1 && cells.y >= 1 && cells.z >= 1 && cells.x < (1u << 31) && cells.y < (1u << 31) &&
                        cells.z < (1u << 31),
                    "a grid of " << cells.x << "x" << cells.y << "x" << cells.z << " cells");
  }

  /// The cell of `p` in `cell` and true, where p is finite and inside the grid (and the clip
  /// box); else false. The reference for four().
  bool one(const glm::vec3& p, glm::uvec3& cell) const {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    const glm::dvec3 q(p);
    const glm::dvec3 c = fastFloor((q - mOrigin) * mInverse);
    if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= mLimit.x || c.y >= mLimit.y || c.z >= mLimit.z) return false;
    if (!mClip.contains(q)) return false;
    cell = glm::uvec3(c);
    return true;
  }

  /// The cells of p[0], ..., p[3] in `cells` and true, where all four are finite and inside the
  /// grid and the clip box (what one() gives each); else false, `cells` unspecified.
  bool four(const glm::vec3* p, CellsOfFour& cells) const {
#if defined(__SSE4_1__)
    static_assert(sizeof(glm::vec3) == 12, "positions are packed x, y, z");
    const float* f = &p[0].x;
    const __m128 a = _mm_loadu_ps(f);                                   // x0 y0 z0 x1
    const __m128 b = _mm_loadu_ps(f + 4);                               // y1 z1 x2 y2
    const __m128 c = _mm_loadu_ps(f + 8);                               // z2 x3 y3 z3
    const __m128 yz01 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 0, 2, 1));  // y0 z0 y1 z1
    const __m128 xy23 = _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 1, 3, 2));  // x2 y2 x3 y3
    __m128i inside = _mm_set1_epi32(-1);
    const __m128i x = axis(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 0, 3, 0)), _mm_shuffle_ps(xy23, xy23, 0x08), 0, inside);
    const __m128i y = axis(_mm_shuffle_ps(yz01, yz01, 0x08), _mm_shuffle_ps(xy23, xy23, 0x0d), 1, inside);
    const __m128i z = axis(_mm_shuffle_ps(yz01, yz01, 0x0d), _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 0, 3, 0)), 2, inside);
    _mm_store_si128(reinterpret_cast<__m128i*>(cells.x), x);
    _mm_store_si128(reinterpret_cast<__m128i*>(cells.y), y);
    _mm_store_si128(reinterpret_cast<__m128i*>(cells.z), z);
    return _mm_movemask_epi8(inside) == 0xffff;
#else
    for (int k = 0; k < 4; ++k) {
      glm::uvec3 cell;
      if (!one(p[k], cell)) return false;
      cells.x[k] = cell.x;
      cells.y[k] = cell.y;
      cells.z[k] = cell.z;
    }
    return true;
#endif
  }

 private:
#if defined(__SSE4_1__)
  /// The cells along axis `a` of the particles whose coordinates are lanes 0 and 1 of `low` and
  /// of `high`, as int32: floor((double(v) - origin) * inverse), the scalar form's operations.
  /// Clears the lanes of `inside` of those outside the grid or the clip box on this axis.
  __m128i axis(__m128 low, __m128 high, int a, __m128i& inside) const {
    const __m128d origin = _mm_set1_pd(mOrigin[a]), inverse = _mm_set1_pd(mInverse);
    const __m128d clipMin = _mm_set1_pd(mClip.min[a]), clipMax = _mm_set1_pd(mClip.max[a]);
    const __m128d ql = _mm_cvtps_pd(low), qh = _mm_cvtps_pd(high);
    const __m128d l = _mm_floor_pd(_mm_mul_pd(_mm_sub_pd(ql, origin), inverse));
    const __m128d h = _mm_floor_pd(_mm_mul_pd(_mm_sub_pd(qh, origin), inverse));
    const __m128i cells = _mm_unpacklo_epi64(_mm_cvttpd_epi32(l), _mm_cvttpd_epi32(h));
    // A cell is inside where it is at most the axis' last, as an unsigned number: a NaN, an
    // infinity or a floor beyond int32 converts to 0x80000000, a negative cell to 2^31 or more.
    const __m128i inGrid = _mm_cmpeq_epi32(_mm_min_epu32(cells, mLast[a]), cells);
    const __m128d clipL = _mm_and_pd(_mm_cmpge_pd(ql, clipMin), _mm_cmple_pd(ql, clipMax));
    const __m128d clipH = _mm_and_pd(_mm_cmpge_pd(qh, clipMin), _mm_cmple_pd(qh, clipMax));
    const __m128i inClip =
        _mm_castps_si128(_mm_shuffle_ps(_mm_castpd_ps(clipL), _mm_castpd_ps(clipH), _MM_SHUFFLE(2, 0, 2, 0)));
    inside = _mm_and_si128(inside, _mm_and_si128(inGrid, inClip));
    return cells;
  }
#endif
  glm::dvec3 mOrigin;
  double mInverse;
  glm::u64vec3 mLimit;
  Box mClip;
#if defined(__SSE4_1__)
  /// Each axis' last cell, in every lane (after mLimit, which initializes it).
  __m128i mLast[3] = {_mm_set1_epi32(int(mLimit.x - 1)), _mm_set1_epi32(int(mLimit.y - 1)),
                      _mm_set1_epi32(int(mLimit.z - 1))};
#endif
};

}  // namespace flipscope::detail
