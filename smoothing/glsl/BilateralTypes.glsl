// Parameters of the bilateral pass (smoothing/glsl/Bilateral.glsl), shared by C++
// (BilateralFilter.cpp checks the layout) and GLSL: a std140 block of four scalars.
struct BilateralParams {
  float worldRadius;  // kernel radius, world units (strength x particle radius): worldRadius * focalPixels / z pixels
  float maxRadius;    // upper bound of the kernel radius, pixels
  float sigmaDepth;   // range Gaussian: standard deviation of the depth difference, world units
  float unused0;
};
