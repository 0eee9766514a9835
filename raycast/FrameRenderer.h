// FrameRenderer: the request-driven frame loop (Reichl et al. 2014 §3.3, §4.4). Each pass traces
// the pending rays; the bricks they stopped at are converted by the Streamer (or found in its
// CPU cache), placed in the BrickPool and uploaded, and the next pass resumes the rays, until no
// ray asks for anything. A cold frame converges in a few passes, a warm one in one; trace()
// streams the bricks of a cold frame's first pass, or all in view, before it (prefetch). Bricks,
// frame indices and the domain come from a BrickSource (streaming/BrickSource.h): a store, or a
// synthetic source in tests.
//
//   FrameRenderer renderer(std::make_shared<StoreBrickSource>(BrickStore::open(dir)),
//                          std::make_unique<CpuRaycaster>(), settings);
//   RenderResult result = renderer.render(frame, camera);
//   RenderImage image = shade(result, camera, ShadingOptions{});
//
// Not thread safe; one renderer per device.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/Box.h"
#include "preprocess/store/BrickStore.h"
#include "raycast/BrickPool.h"
#include "raycast/Camera.h"
#include "raycast/FoamSettings.h"
#include "raycast/RaycastDevice.h"
#include "streaming/BrickSource.h"
#include "streaming/Streamer.h"

namespace flipscope {

struct RenderSettings {
  std::uint32_t width = 1280;
  std::uint32_t height = 720;
  float radius = 1.0f;   ///< sphere radius in cells
  float jitter = 0.25f;  ///< largest jitter offset in cells (§3.2.2); 0 turns jitter off
  /// The most the brick pool on the device may take; it takes what the frames rendered fill.
  std::uint64_t gpuBudgetBytes = std::uint64_t(1) << 30;
  std::uint64_t cpuCacheBytes = std::uint64_t(2) << 30;   ///< converted bricks, all frames
  unsigned threads = 0;                                   ///< conversion workers; 0: all cores
  int maxPasses = 1000;
  int readAheadFrames = 0;
  FoamSettings foam;  ///< §3.5
  /// Liquid cells at which the thickness trace behind a hit stops, absorption having saturated
  /// (§3.6; FramePipeline derives it from the shading's absorption); 0: no thickness.
  float thicknessSaturationCells = 64.0f;
  /// Whether a store's per-particle attribute is read at all: false where the image shows none
  /// (resolve() decides). FramePipeline's store gives bricks without it then
  /// (StoreBrickSource); the renderer follows what its source carries.
  bool attributes = true;
  /// Whether trace() streams, before a cold frame's first pass, the bricks that pass would
  /// request (firstBricksAlongRays: the first brick along each of a grid of the image's rays),
  /// when the pool holds them beside the frame's resident ones; or all those in view
  /// (boxMayBeInView) where they are at most twice as many and the pool holds the whole frame
  /// (poolHoldsFrame). §3.3's loop streams the rest, what the rays meet behind them. 20 M
  /// particles at 1280x720 on 2 cores: 30 bricks in view, 21 first; one pass of 93 to 101 ms
  /// instead of three of about 30, 72 and 18. 500 M: 1115 of the 2468 bricks in view are
  /// reached, and only the first pass's 453 are streamed ahead.
  bool prefetch = true;
};
/// Throws InputError naming the setting that is out of range.
void validate(const RenderSettings& settings);
/// Cells around a cell whose spheres can reach it: ceil(radius + jitter + 0.5) - 1.
std::uint32_t sphereReach(float radius, float jitter);
/// The overlap border the pool's bricks are converted with: the sphere reach, and with foam
/// enough that every cell the ray-caster reads is classified from its whole neighbourhood (reach
/// + the radius; 6 for the volume's trilinear 4^3 blocks), at most kMaxOverlap (beyond it a
/// cell near a brick face sees only the neighbours within the border).
std::uint32_t storedOverlap(const RenderSettings& settings);
/// The sphere radius in cells a render takes when none is given: kDefaultRadiusPerSpacing particle
/// spacings of the store (StoreHeader::particleSpacing), so the spheres of neighbouring particles
/// overlap and a liquid body renders closed even where a FLIP sheet is one or two particles
/// thin; at least 1 cell, at most what the overlap border allows with `jitter`; 1 cell when the
/// store records no spacing.
float defaultSphereRadius(const StoreHeader& header, float jitter);
/// 1.5: Blender's Mantaflow meshes its particles with a radius of one simulation voxel, about 1.6
/// particle spacings at its default of 8 particles per voxel.
inline constexpr double kDefaultRadiusPerSpacing = 1.5;

struct RenderStats {
  int passes = 0;
  bool converged = false;             ///< no ray pending at the end (false: pass limit reached)
  std::uint64_t bricksRequested = 0;  ///< summed over passes (and trace()'s prefetch)
  std::uint64_t bricksUploaded = 0;
  std::uint64_t bricksEvicted = 0;
  std::uint64_t bricksClassified = 0;  ///< foam classification (§3.5), of uploaded bricks
  std::size_t bricksResident = 0;  ///< in the pool after the frame, all frames
  std::size_t frameBricks = 0;     ///< non-empty bricks of the frame
  std::uint64_t poolBytes = 0;     ///< device memory of the brick pool
  double traceMs = 0;              ///< device time of the passes (GL timer queries on the GPU)
  double streamMs = 0;             ///< waiting for the Streamer (conversion or CPU cache)
  double uploadMs = 0;
  double foamMs = 0;  ///< foam classification on the device
  double totalMs = 0;
};

struct RenderResult {
  int frame = 0;
  std::uint32_t width = 0, height = 0;
  std::vector<RayHit> hits;  ///< row 0 at the top
  RenderStats stats;
};

class FrameRenderer {
 public:
  /// `source` is shared with the renderer's Streamer (its workers read() from it). Throws
  /// InputError for bad settings.
  FrameRenderer(std::shared_ptr<BrickSource> source, std::unique_ptr<RaycastDevice> device,
                const RenderSettings& settings);
  ~FrameRenderer();

  /// Renders `frame` (InputError when the source has no such frame; FileError naming the
  /// source when a brick cannot be read). `direction` (+1, -1, 0) steers the Streamer's
  /// read-ahead.
  RenderResult render(int frame, const Camera& camera, int direction = 0);
  /// render() without reading the hits back: they stay on the device for the screen-space
  /// stages (pipeline/FramePipeline.h). begin(), then passes that wait for the Streamer until
  /// the frame converges or the pass limit is reached.
  RenderStats trace(int frame, const Camera& camera, int direction = 0);

  /// Progressive rendering for the viewer (§3.3: "this rendering can only be performed in the
  /// next frame"). begin() starts `frame` with every ray fresh and traces nothing; each
  /// advance() then runs passes for about `budgetMs` and returns without waiting for the
  /// Streamer: bricks still converting stay requested, their rays pending, and the pass after
  /// they arrive resumes them. A pass runs only when a brick was uploaded since the last one (or
  /// at the start), so a slice that finds nothing new costs no trace. The same errors as
  /// trace(); advance() without begin() is a LogicError.
  void begin(int frame, const Camera& camera, int direction = 0);
  /// The begun frame's statistics so far; `changed` says whether any pass ran in this call.
  const RenderStats& advance(double budgetMs, bool* changed = nullptr);
  /// Converged, or stopped at the pass limit.
  bool finished() const;

  BrickSource& source() const { return *mSource; }
  RaycastDevice& device() { return *mDevice; }
  const RenderSettings& settings() const { return mSettings; }
  const Streamer& streamer() const { return *mStreamer; }
  /// The pool as it is now: grown to what the frames rendered so far fill, within the budget.
  const PoolLayout& poolLayout() const { return mPool.layout(); }
  /// World box of the occupied cells of frames [first, last] (empty box when they hold no
  /// brick). Cell-exact from the bricks on the outer layers, or brick-exact when more than a
  /// few thousand bricks form them across the range.
  Box occupiedBounds(int first, int last) const;
  Box occupiedBounds(int frame) const { return occupiedBounds(frame, frame); }
  /// The parameter block of a pass (exposed for tests).
  RaycastParams params(const Camera& camera, const FrameIndex& frame) const;
  /// The foam classification block for a batch of `slots` uploaded bricks (exposed for tests).
  FoamClassifyParams foamParams(std::size_t slots) const;

 private:
  struct ActiveFrame;
  std::vector<std::uint32_t> pageTable(const FrameIndex& frame) const;
  /// Runs passes of the active frame: waiting for every requested brick (trace()), or until
  /// `budgetMs` has passed or nothing new is ready (advance()).
  void runPasses(bool wait, double budgetMs, bool* changed);
  /// Reallocates the pool for `wanted` slots (twice its slots at least, the budget's at most)
  /// when it has fewer and the budget allows more; the bricks it held are gone. Whether it did.
  bool growPool(std::uint64_t wanted);
  /// Places and uploads `bricks` of the active frame nearest to the eye first, then classifies
  /// their foam.
  void upload(std::vector<std::shared_ptr<const ConvertedBrick>> bricks);
  /// Waits until the Streamer has converted (or found in its CPU cache) every brick of the
  /// active frame at `coords`, requested before, then uploads them.
  void streamAndUpload(const std::vector<glm::uvec3>& coords);
  /// RenderSettings::prefetch for the frame begun.
  void prefetch(const Camera& camera);
  /// Whether the pool holds a frame of `frameBricks` bricks all at once, so that none of them
  /// evicts another: a slot each, and an attribute ring with room for twice the most they take.
  bool poolHoldsFrame(std::size_t frameBricks) const;

  std::shared_ptr<BrickSource> mSource;
  std::unique_ptr<RaycastDevice> mDevice;
  RenderSettings mSettings;
  std::uint32_t mReach = 0;
  std::uint32_t mOverlap = 0;
  /// The pool the budget allows (RenderSettings::gpuBudgetBytes). The pool begins at 3 slots and
  /// grows towards it as frames need (growPool): a store smaller than the budget takes only what
  /// its frames fill.
  PoolLayout mBudgetPool;
  BrickPool mPool;
  std::unique_ptr<Streamer> mStreamer;
  std::uint64_t mBatch = 0;
  std::unique_ptr<ActiveFrame> mActive;
};

}  // namespace flipscope
