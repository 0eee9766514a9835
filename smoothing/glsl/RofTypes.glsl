// Parameters of the ROF passes (smoothing/glsl/Rof.glsl), shared by C++ (RofFilter.cpp checks
// the layout) and GLSL: a std140 block of four scalars.
struct RofParams {
  float lambda0;  // eq. 7: lambda_ij = lambda0 / (z_ij + epsilon), world units x pixels x world units
  float epsilon;  // eq. 7, world units
  float tau;      // eq. 2 step, 0.25
  uint adaptive;  // 1: update lambda every iteration by eq. 7; 0: keep lambda^(0)
};
