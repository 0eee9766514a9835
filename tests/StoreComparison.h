// Comparing two brick stores frame by frame: the same brick table (coordinates, counts, sizes,
// offsets, checksums) and the same payloads. Stores converted from the same input in any way
// (serially, out of core, by concurrent or farm writers) must match, but for their ids.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

#include "preprocess/store/BrickStore.h"

namespace flipscope::testing {

/// Expects `actual` to hold exactly the frames of `expected`, each with the same bricks.
inline void expectSameFrames(const std::filesystem::path& expected, const std::filesystem::path& actual) {
  const BrickStore a = BrickStore::open(expected), b = BrickStore::open(actual);
  const StoreHeader &ha = a.header(), &hb = b.header();
  EXPECT_EQ(ha.cellSize, hb.cellSize);
  EXPECT_EQ(ha.origin, hb.origin);
  EXPECT_EQ(ha.brickGrid, hb.brickGrid);
  EXPECT_EQ(ha.brickSize, hb.brickSize);
  EXPECT_EQ(ha.attribute, hb.attribute);
  EXPECT_EQ(ha.particleSpacing, hb.particleSpacing);
  ASSERT_EQ(a.frames(), b.frames()) << actual;
  for (int f : a.frames()) {
    const auto fa = a.frame(f), fb = b.frame(f);
    EXPECT_EQ(fa->stats.particles, fb->stats.particles) << "frame " << f;
    ASSERT_EQ(fa->bricks.size(), fb->bricks.size()) << "frame " << f;
    for (std::size_t i = 0; i < fa->bricks.size(); ++i) {
      const BrickRecord &ra = fa->bricks[i], &rb = fb->bricks[i];
      EXPECT_TRUE(ra.coord == rb.coord && ra.particles == rb.particles && ra.cells == rb.cells &&
                  ra.bytes == rb.bytes && ra.offset == rb.offset && ra.checksum == rb.checksum)
          << "frame " << f << " brick " << i;
      EXPECT_EQ(a.readPayload(*fa, std::uint32_t(i)), b.readPayload(*fb, std::uint32_t(i)))
          << "frame " << f << " brick " << i;
    }
  }
}

}  // namespace flipscope::testing
