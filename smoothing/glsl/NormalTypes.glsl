// Parameters of the normal reconstruction pass (smoothing/glsl/Normals.glsl), shared by C++ and
// GLSL: a std140 block of four scalars.
struct NormalParams {
  float edgeDepth;  // world units: neighbours farther in depth lie across an edge
  float unused0;
  float unused1;
  float unused2;
};
