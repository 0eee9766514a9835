// Parameters of the narrow-range passes (smoothing/glsl/NarrowRange.glsl), shared by C++
// (NarrowRangeFilter.cpp checks the layout) and GLSL: a std140 block of two groups of four
// scalars.
struct NarrowRangeParams {
  float worldRadius;  // kernel radius, world units (strength x particle radius): worldRadius * focalPixels / z pixels
  float maxRadius;    // upper bound of the kernel radius of this pass, pixels
  float threshold;    // delta: half width of the narrow depth range, world units
  float clampOffset;  // mu: a sample behind the range counts as the pixel's depth + mu, world units
  int axisX;          // narrowRange1D: the direction of the pass, (1, 0) or (0, 1)
  int axisY;
  float unused0;
  float unused1;
};
