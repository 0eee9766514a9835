// Parameters of the plane-fit passes (smoothing/glsl/PlaneFit.glsl), shared by C++
// (PlaneFitFilter.cpp checks the layout) and GLSL: a std140 block of four scalars.
struct PlaneFitParams {
  float worldRadius;     // window radius, world units (strength x particle radius): worldRadius * focalPixels / z pixels
  float maxRadius;       // the window radius at most, pixels
  float invSigma2;       // 1 / sigma^2 of the depth weight exp(-(z_i - z_j)^2 / sigma^2), 1 / world units^2
  float moveLimit;       // the largest depth change of one iteration, in world radii of the window
};
