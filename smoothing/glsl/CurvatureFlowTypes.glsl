// Parameters of the curvature-flow passes (smoothing/glsl/CurvatureFlow.glsl), shared by C++
// (CurvatureFlowFilter.cpp checks the layout) and GLSL: a std140 block of two groups of four
// scalars.
struct CurvatureFlowParams {
  float cx;            // van der Laan et al. 2009 eq. 5.4: Cx = 2 / (Vx Fx) = 2 tan(fov/2) aspect / width
  float cy;            // Cy = 2 / (Vy Fy) = 2 tan(fov/2) / height
  float stepPerDepth;  // the Euler time step at depth z is stepPerDepth * z (world units)
  float jumpBase;      // a neighbour is across a depth discontinuity when |dz| > jumpBase +
  float jumpPerDepth;  //   jumpPerDepth * (the smaller of the two depths); world units, 1 / pixel
  float unused0;
  float unused1;
  float unused2;
};
