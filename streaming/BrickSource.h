// Where bricks come from: an interface, so the Streamer, the frame renderer
// (raycast/FrameRenderer.h) and the frame pipeline run on a synthetic source in tests and
// benchmarks as well as on a store, and its adapter over the preprocess BrickStore (Reichl et al.
// 2014 §3.1: the CPU converts bricks on request from the binned particles).
//
// A source describes a fixed domain (the store-wide StoreHeader: brick size, brick grid,
// origin, cell size, attribute kind) and a set of frames; each frame has an index (its
// non-empty bricks in Morton order and the presence octree over them, PresenceOctree.h) and
// the particles of each of those bricks. Everything a renderer needs comes through here.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Box.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {

/// A brick of one frame, by brick-grid coordinates.
struct BrickKey {
  int frame = 0;
  glm::uvec3 coord{0};
  bool operator==(const BrickKey&) const = default;
};

struct BrickKeyHash {
  std::size_t operator()(const BrickKey& key) const {
    std::uint64_t h = std::uint64_t(std::uint32_t(key.frame)) * 0x9e3779b97f4a7c15ull;
    h ^= (std::uint64_t(key.coord.x) | std::uint64_t(key.coord.y) << 21 | std::uint64_t(key.coord.z) << 42) +
         0x632be59bd9b4e019ull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};

/// Contract:
/// - header() is the same for the source's lifetime and for every frame. Its brick size is 32,
///   64 or 128, its brick grid below kMortonAxisLimit per axis, its cell size > 0; `version` and
///   `particleSpacing` (0: unknown) are informative only.
/// - frames() lists the frame numbers, ascending and unique; hasFrame(f) agrees with it.
/// - frame(f) is the same index on every call for the source's lifetime: frame == f, `bricks`
///   are exactly the bricks whose read() returns particles, unique, in ascending Morton order of
///   their coordinates (core/Morton.h), each with its particle and cell counts, and `octree` is
///   PresenceOctree::build over those codes for the largest axis of the brick grid. `file` and
///   `fileBytes` may be empty / 0 for a source without files.
/// - read(key) returns the particles of a brick listed in frame(key.frame), the same on every
///   call, and nullptr for every other key.
/// Thread safety: every member may be called from any number of threads at once (the
/// Streamer's workers read() while the renderer asks for frame indices).
class BrickSource {
 public:
  virtual ~BrickSource() = default;

  /// The store-wide constants: domain (origin, cell size, brick grid), brick size, attribute.
  virtual const StoreHeader& header() const = 0;
  std::uint32_t brickSize() const { return header().brickSize; }
  /// Frame numbers present, ascending.
  virtual std::vector<int> frames() const = 0;
  virtual bool hasFrame(int frame) const;
  /// The frame's index (bricks and presence octree, see the contract above). Throws InputError
  /// when the source has no such frame, FileError when a store's index is corrupted.
  virtual std::shared_ptr<const FrameIndex> frame(int frame) const = 0;
  /// The brick's particles, or nullptr when the brick is empty, outside the grid, or the frame
  /// does not exist. Throws FileError on a corrupted store.
  virtual std::shared_ptr<const DecodedBrick> read(const BrickKey& key) = 0;
  /// Whether the bricks read() gives carry the per-particle attribute values the header names
  /// (DecodedBrick::attributes); what the ray-caster converts and pools. A source may leave
  /// them out (StoreBrickSource).
  virtual bool carriesAttributes() const { return header().attribute != AttributeKind::None; }
  /// What error messages call the source: a store's directory, or a synthetic source's
  /// description.
  virtual std::string name() const = 0;
};

/// Reads bricks from a BrickStore through each frame's presence octree. name() is the store
/// directory. Without `attributes`, its bricks leave the store's attribute values compressed
/// and out (BrickStore::readBrick): for an image that shows none, they were most of a cold
/// frame's streaming (20 M particles: about 104 ms, then 43) and a ring in the pool.
class StoreBrickSource : public BrickSource {
 public:
  explicit StoreBrickSource(BrickStore store, bool attributes = true)
      : mStore(std::move(store)), mAttributes(attributes) {}
  const StoreHeader& header() const override { return mStore.header(); }
  std::vector<int> frames() const override { return mStore.frames(); }
  bool hasFrame(int frame) const override { return mStore.hasFrame(frame); }
  std::shared_ptr<const FrameIndex> frame(int frame) const override { return mStore.frame(frame); }
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override;
  bool carriesAttributes() const override { return mAttributes && BrickSource::carriesAttributes(); }
  std::string name() const override { return mStore.directory().string(); }

  const BrickStore& store() const { return mStore; }
  /// BrickStore::reloadFrameTable: frames a concurrent convert listed since. Thread safe.
  bool reloadFrames() { return mStore.reloadFrameTable(); }

 private:
  BrickStore mStore;
  bool mAttributes;
};

/// World box of the occupied cells of frames [first, last] of `source` (those it has; empty box
/// when they hold no brick). Cell-exact from the bricks on the outer layers, or brick-exact when
/// more than a few thousand bricks form them across the range.
Box occupiedBounds(BrickSource& source, int first, int last);

/// What a default camera frames (framedBounds): the occupied cells, less particles far away.
struct FramedBounds {
  Box box;                             ///< as occupiedBounds, over the bricks kept
  std::uint64_t particlesLeftOut = 0;  ///< of the bricks left out, the most in any one frame
  std::uint64_t particles = 0;         ///< of every brick, over all frames of the range
};

/// The box a default camera frames over frames [first, last]: occupiedBounds of the bricks that
/// lie near the bulk of the particles. Per axis, the bulk is the range of brick coordinates that
/// holds all but kFramingTail of the particles at each end (by the bricks' particle counts); a
/// brick is kept when, along every axis, it lies within the bulk's longest extent of the bulk.
/// So spray and splashes within a tank's size of the liquid are framed, and the few particles a
/// solver flung ten thousand tank sizes away (whose bricks the domain then holds) are not, where
/// framing them would leave the liquid a speck. Below 1 / kFramingTail particles over the range
/// the tails are empty: nothing is left out. Frames of the range the source lacks are skipped.
FramedBounds framedBounds(BrickSource& source, int first, int last);
inline constexpr double kFramingTail = 5e-4;
static_assert(kFramingTail < 0.5, "the tails at both ends leave a bulk");

}  // namespace flipscope
