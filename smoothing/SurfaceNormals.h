// Normals of the smoothed surface for deferred shading (Reichl et al. 2014 §3.3, Fig. 3), from
// the depth image alone: eye-relative positions of neighbouring pixels, one-sided differences
// that never cross a depth edge (van der Laan et al. 2009 §4).
#pragma once

#include "smoothing/ScreenDevice.h"

namespace flipscope {

/// Writes into `normals` (xyz: unit world-space normal facing the camera, w: mask) the normals
/// of `depth` (x: linear depth, y: mask). Neighbours more than `edgeParticles` particle radii
/// apart in depth lie across an edge.
void reconstructNormals(ScreenDevice& device, ScreenImage depth, ScreenImage normals, float edgeParticles = 4.0f);

}  // namespace flipscope
