// FirstBricks: the bricks a cold frame's first pass would request (Reichl et al. 2014 §3.3).
// With nothing of the frame resident, a ray stops at, and requests, the first brick of the
// presence octree that it enters; a walk of the brick grid on the CPU finds the same bricks for a
// grid of the image's rays, so FrameRenderer can stream them before that pass instead of after.
#pragma once

#include <cstdint>
#include <vector>

#include "preprocess/store/BrickStore.h"
#include "raycast/Camera.h"

namespace flipscope {

/// The rays firstBricksAlongRays walks at most, about: every stride-th pixel each way.
inline constexpr std::uint32_t kFirstBrickRays = 16384;

/// The pixel stride for a width x height image: 1 up to kFirstBrickRays pixels, then the
/// smallest that keeps the rays at most about that many.
std::uint32_t firstBrickStride(std::uint32_t width, std::uint32_t height);

/// The distinct bricks (indices into the frame's brick table, ascending) that the rays through
/// the centres of pixels (stride i + stride / 2, stride j + stride / 2) (pixelRay; the last row
/// and column at most) enter first among the bricks `octree` holds. A ray is walked in double
/// precision from cell to cell of the brick grid (Amanatides and Woo), where the ray-caster
/// walks in floats, so a ray that grazes a brick's edge may find another: a hint, not the
/// first pass's exact requests.
std::vector<std::uint32_t> firstBricksAlongRays(const Camera& camera, std::uint32_t width, std::uint32_t height,
                                               std::uint32_t stride, const StoreHeader& header,
                                               const PresenceOctree& octree);

}  // namespace flipscope
