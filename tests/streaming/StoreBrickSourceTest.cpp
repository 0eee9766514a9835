// StoreBrickSource reads the same bricks back that were written to a BrickStore, and the
// Streamer over it converts them like over the in-memory source; the synthetic source's frame
// index is the one a store holds for the same bricks.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <limits>

#include <glm/common.hpp>

#include "core/Error.h"
#include "core/Morton.h"
#include "preprocess/store/FrameFile.h"
#include "streaming/Streamer.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope {
namespace {

class StoreBrickSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    mDir = std::filesystem::temp_directory_path() /
           ("flipscope-store-source-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
            std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::remove_all(mDir);
    StoreHeader header;
    header.brickSize = 32;
    header.cellSize = 0.01;
    header.brickGrid = mGrid;
    header.attribute = AttributeKind::Speed;
    header.attributeName = "speed";
    BrickStore store = BrickStore::createOrAppend(mDir, header);
    std::vector<glm::uvec3> coords = mSynthetic.bricks(1);
    std::sort(coords.begin(), coords.end(),
              [](glm::uvec3 a, glm::uvec3 b) { return mortonEncode3(a.x, a.y, a.z) < mortonEncode3(b.x, b.y, b.z); });
    FrameWriter writer(store.framePath(1), store.header(), 1);  // carries the store id
    FrameStats stats;
    for (glm::uvec3 c : coords) {
      auto brick = mSynthetic.read({1, c});
      if (!brick) continue;
      writer.addBrick(c, std::uint32_t(brick->particleCount()), std::uint32_t(brick->cells.size()),
                      encodeBrick(*brick, 1, kAttributeCoding));
      stats.particles += brick->particleCount();
    }
    writer.finish(stats);
    store.addFrame(1);
  }
  void TearDown() override { std::filesystem::remove_all(mDir); }

  const glm::uvec3 mGrid{3, 3, 3};
  SyntheticBrickSource mSynthetic{32, mGrid, 3, 0.3};
  std::filesystem::path mDir;
};

TEST_F(StoreBrickSourceTest, ReadsWhatWasWritten) {
  StoreBrickSource source(BrickStore::open(mDir));
  EXPECT_EQ(source.brickSize(), 32u);
  for (std::uint32_t z = 0; z < 4; ++z)
    for (std::uint32_t y = 0; y < 3; ++y)
      for (std::uint32_t x = 0; x < 3; ++x) {
        auto expected = mSynthetic.read({1, {x, y, z}});
        auto read = source.read({1, {x, y, z}});
        ASSERT_EQ(read != nullptr, expected != nullptr) << x << "," << y << "," << z;
        if (!read) continue;
        EXPECT_EQ(read->cells, expected->cells);
        EXPECT_EQ(read->counts, expected->counts);
        EXPECT_EQ(read->attributes, expected->attributes);
      }
  EXPECT_EQ(source.read({0, {0, 0, 0}}), nullptr);            // no such frame
  EXPECT_EQ(source.read({1, {0xffffffffu, 0, 0}}), nullptr);  // outside the grid
}

/// A brick of a one-frame store: its cells (brick-local) and the particles in each.
struct CellsOfBrick {
  glm::uvec3 coord;
  std::vector<glm::uvec3> cells;
  std::uint32_t particlesPerCell = 1;
};

/// Writes frame `frame` of `store` (bricks of 32) holding `bricks`.
void writeFrame(BrickStore& store, int frame, const std::vector<CellsOfBrick>& bricks) {
  std::vector<const CellsOfBrick*> order;
  for (const CellsOfBrick& b : bricks) order.push_back(&b);
  std::sort(order.begin(), order.end(), [&](const CellsOfBrick* a, const CellsOfBrick* b) {
    return mortonEncode3(a->coord.x, a->coord.y, a->coord.z) < mortonEncode3(b->coord.x, b->coord.y, b->coord.z);
  });
  FrameWriter writer(store.framePath(frame), store.header(), frame);
  FrameStats stats;
  for (const CellsOfBrick* b : order) {
    DecodedBrick brick;
    for (const glm::uvec3 c : b->cells) brick.cells.push_back(c.x + 32 * (c.y + 32 * c.z));
    std::sort(brick.cells.begin(), brick.cells.end());
    brick.counts.assign(brick.cells.size(), b->particlesPerCell);
    const auto particles = std::uint32_t(brick.cells.size()) * b->particlesPerCell;
    writer.addBrick(b->coord, particles, std::uint32_t(brick.cells.size()), encodeBrick(brick, 1, kAttributeCoding));
    stats.particles += particles;
  }
  writer.finish(stats);
  store.addFrame(frame);
}

/// Writes frame 0 of a store of bricks of 32 at `dir` (emptied first) holding `bricks`.
void writeStore(const std::filesystem::path& dir, const StoreHeader& header, const std::vector<CellsOfBrick>& bricks) {
  std::filesystem::remove_all(dir);
  BrickStore store = BrickStore::createOrAppend(dir, header);
  writeFrame(store, 0, bricks);
}

std::filesystem::path testDirectory(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("flipscope-" + name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
}

/// World box of the cells of `bricks`, one by one.
Box cellBox(const StoreHeader& header, const std::vector<CellsOfBrick>& bricks) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const CellsOfBrick& b : bricks)
    for (const glm::uvec3 c : b.cells) {
      lo = glm::min(lo, glm::dvec3(b.coord * 32u + c));
      hi = glm::max(hi, glm::dvec3(b.coord * 32u + c) + 1.0);
    }
  return Box{header.origin + lo * header.cellSize, header.origin + hi * header.cellSize};
}

TEST(OccupiedBounds, AreTheCellBoundsOfEveryBrick) {
  // occupiedBounds decodes the outer bricks only; every brick's cells, one by one, give the same.
  // A few cells in bricks of 32 on a 4x3x3 grid, none on a brick's face but one.
  const auto dir = testDirectory("occupied");
  StoreHeader header;
  header.brickSize = 32;
  header.cellSize = 0.25;
  header.origin = {-1, 2, 0.5};
  header.brickGrid = {4, 3, 3};
  const std::vector<CellsOfBrick> bricks = {
      {{0, 1, 2}, {{5, 7, 9}, {30, 2, 3}}},
      {{2, 0, 1}, {{1, 31, 0}}},
      {{1, 1, 1}, {{0, 0, 0}}},  // inside: never decoded
      {{3, 2, 0}, {{12, 4, 17}, {6, 20, 21}}},
  };
  writeStore(dir, header, bricks);
  StoreBrickSource source(BrickStore::open(dir));
  const Box bounds = occupiedBounds(source, 0, 0);
  const Box expected = cellBox(header, bricks);
  EXPECT_EQ(bounds.min, expected.min);
  EXPECT_EQ(bounds.max, expected.max);
  std::filesystem::remove_all(dir);
}

TEST(FramedBounds, LeaveOutAFewParticlesFarAwayAndKeepSprayNearAndManyFar) {
  // The bulk: 8 bricks of 2 cells of 500 particles (8000), x in [0, 3] and y in [0, 1]: its
  // longest extent is 4 bricks, so bricks up to x = 3 + 4 = 7 are near it. The tail at each end
  // is 8000 * kFramingTail = 4 particles.
  const auto dir = testDirectory("framed");
  StoreHeader header;
  header.brickSize = 32;
  header.cellSize = 0.5;
  header.origin = {3, -2, 1};
  header.brickGrid = {64, 64, 2};
  std::vector<CellsOfBrick> bulk;
  for (std::uint32_t x = 0; x < 4; ++x)
    for (std::uint32_t y = 0; y < 2; ++y) bulk.push_back({{x, y, 0}, {{3, 9, 4}, {20, 17, 28}}, 500});
  const auto framed = [&](const std::vector<CellsOfBrick>& extra) {
    std::vector<CellsOfBrick> all = bulk;
    all.insert(all.end(), extra.begin(), extra.end());
    writeStore(dir, header, all);
    StoreBrickSource source(BrickStore::open(dir));
    const FramedBounds f = framedBounds(source, 0, 0);
    const Box occupied = occupiedBounds(source, 0, 0);
    EXPECT_EQ(occupied.min, cellBox(header, all).min);
    EXPECT_EQ(occupied.max, cellBox(header, all).max);
    return f;
  };
  const Box bulkBox = cellBox(header, bulk);

  // Four particles flung far along x and one far along y (each in a tail of at most 4): left out.
  FramedBounds f = framed({{{60, 0, 0}, {{1, 1, 1}}, 4}, {{2, 63, 1}, {{31, 31, 31}}}});
  EXPECT_EQ(f.particles, 8005u);
  EXPECT_EQ(f.particlesLeftOut, 5u);
  EXPECT_EQ(f.box.min, bulkBox.min);
  EXPECT_EQ(f.box.max, bulkBox.max);

  // Spray a bulk's extent away (brick x = 7), and beside the bulk above it (y = 5): framed.
  const std::vector<CellsOfBrick> spray = {{{7, 0, 0}, {{31, 0, 0}}}, {{1, 5, 1}, {{0, 31, 31}}}};
  f = framed(spray);
  EXPECT_EQ(f.particlesLeftOut, 0u);
  std::vector<CellsOfBrick> withSpray = bulk;
  withSpray.insert(withSpray.end(), spray.begin(), spray.end());
  EXPECT_EQ(f.box.min, cellBox(header, withSpray).min);
  EXPECT_EQ(f.box.max, cellBox(header, withSpray).max);

  // One brick further (x = 8): left out. Five particles there (more than the tail): framed.
  f = framed({{{8, 0, 0}, {{0, 0, 0}}}});
  EXPECT_EQ(f.particlesLeftOut, 1u);
  EXPECT_EQ(f.box.max, bulkBox.max);
  f = framed({{{60, 0, 0}, {{0, 0, 0}}, 5}});
  EXPECT_EQ(f.particlesLeftOut, 0u);
  EXPECT_EQ(f.box.max.x, header.origin.x + (60 * 32 + 1) * header.cellSize);

  // A flipbook over frames 0 to 4 of a store with frames 0 and 4 only, each with one particle
  // flung far away (in another brick): both frames are framed, the frames between skipped, and
  // one particle a frame is left out.
  std::vector<CellsOfBrick> frame0 = bulk, frame4 = bulk;
  frame0.push_back({{60, 0, 0}, {{1, 1, 1}}});
  frame4.push_back({{61, 0, 0}, {{1, 1, 1}}});
  frame4.push_back({{4, 0, 0}, {{30, 2, 2}}});  // within the bulk's extent: framed
  writeStore(dir, header, frame0);
  {
    BrickStore store = BrickStore::createOrAppend(dir, header);
    writeFrame(store, 4, frame4);
  }
  StoreBrickSource source(BrickStore::open(dir));
  f = framedBounds(source, 0, 4);
  EXPECT_EQ(f.particles, 2 * 8000u + 3);
  EXPECT_EQ(f.particlesLeftOut, 1u) << "the most in one frame";
  EXPECT_EQ(f.box.max.x, cellBox(header, {frame4.back()}).max.x);
  EXPECT_EQ(occupiedBounds(source, 0, 4).max.x, cellBox(header, {frame4[frame4.size() - 2]}).max.x);
  std::filesystem::remove_all(dir);
}

TEST_F(StoreBrickSourceTest, StreamerOverTheStoreMatchesTheInMemorySource) {
  StreamerOptions options;
  options.conversion = {32, 3, AttributeReduction::Max};
  options.threads = 2;
  Streamer fromStore(std::make_shared<StoreBrickSource>(BrickStore::open(mDir)), options);
  Streamer fromMemory(std::make_shared<SyntheticBrickSource>(32, mGrid, 3, 0.3), options);
  std::vector<glm::uvec3> coords = mSynthetic.bricks(1);
  for (Streamer* s : {&fromStore, &fromMemory}) {
    s->setFrame(1);
    s->request(coords);
    s->waitIdle();
  }
  auto a = fromStore.takeReady(1000), b = fromMemory.takeReady(1000);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  auto byMorton = [](const auto& l, const auto& r) {
    return mortonEncode3(l->key.coord.x, l->key.coord.y, l->key.coord.z) <
           mortonEncode3(r->key.coord.x, r->key.coord.y, r->key.coord.z);
  };
  std::sort(a.begin(), a.end(), byMorton);
  std::sort(b.begin(), b.end(), byMorton);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i]->key, b[i]->key);
    EXPECT_EQ(a[i]->bits, b[i]->bits);
  }
  EXPECT_EQ(fromStore.stats().failed, 0u) << fromStore.lastError();
}

TEST_F(StoreBrickSourceTest, SyntheticFrameIndexIsTheStoresIndex) {
  StoreBrickSource store(BrickStore::open(mDir));
  EXPECT_EQ(store.name(), mDir.string());
  EXPECT_EQ(store.frames(), std::vector<int>{1});
  EXPECT_TRUE(store.hasFrame(1));
  EXPECT_FALSE(store.hasFrame(0));
  const auto expected = store.frame(1);
  const auto index = mSynthetic.frame(1);
  EXPECT_EQ(index->frame, 1);
  ASSERT_EQ(index->bricks.size(), expected->bricks.size());
  ASSERT_FALSE(index->bricks.empty());
  for (std::size_t i = 0; i < index->bricks.size(); ++i) {
    EXPECT_EQ(index->bricks[i].coord, expected->bricks[i].coord) << i;
    EXPECT_EQ(index->bricks[i].particles, expected->bricks[i].particles) << i;
    EXPECT_EQ(index->bricks[i].cells, expected->bricks[i].cells) << i;
  }
  EXPECT_EQ(index->octree.levels, expected->octree.levels);
  EXPECT_EQ(index->octree.nodes, expected->octree.nodes);
  EXPECT_EQ(index->stats.particles, expected->stats.particles);
  EXPECT_EQ(mSynthetic.frame(1), index) << "computed once, then cached";
  // Exactly the listed bricks read as non-empty.
  for (std::uint32_t z = 0; z < mGrid.z; ++z)
    for (std::uint32_t y = 0; y < mGrid.y; ++y)
      for (std::uint32_t x = 0; x < mGrid.x; ++x)
        EXPECT_EQ(mSynthetic.read({1, {x, y, z}}) != nullptr, index->octree.find({x, y, z}) >= 0)
            << x << "," << y << "," << z;

  const StoreHeader& h = mSynthetic.header();
  EXPECT_EQ(h.brickSize, 32u);
  EXPECT_EQ(h.brickGrid, mGrid);
  EXPECT_EQ(h.cellSize, SyntheticBrickSource::kCellSize);
  EXPECT_EQ(h.attribute, AttributeKind::Speed);
  EXPECT_EQ(h.origin, glm::dvec3(-0.48, -0.48, 0.0));  // centred on the z axis, floor at z = 0
  EXPECT_EQ(mSynthetic.frames(), (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(mSynthetic.hasFrame(2));
  EXPECT_FALSE(mSynthetic.hasFrame(3));
  EXPECT_THROW(mSynthetic.frame(3), InputError);
  EXPECT_THROW(store.frame(0), InputError);
}

}  // namespace
}  // namespace flipscope
