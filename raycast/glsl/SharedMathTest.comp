// Test shader of tests/raycast/GlContextGlTest.cpp: runs the GLSL side of the C++/GLSL shared
// math (core/glsl/Morton.glsl, streaming/glsl/Jitter.glsl) on random inputs, one invocation per
// input, so the test can compare it with the C++ side (core/Morton.h, streaming/Jitter.h).
// Morton.glsl is included twice on purpose: ShaderSource pastes each file once.
layout(local_size_x = 64) in;

#include "Morton.glsl"
#include "Jitter.glsl"
#include "core/glsl/Morton.glsl"

layout(std140, binding = 0) uniform ParamsBlock {
  uint count;       // inputs
  float maxJitter;  // cellJitter's maxJitter
};
layout(std430, binding = 0) readonly buffer InputBuffer { uvec4 inputs[]; };  // cell x, y, z; timeStep
layout(std430, binding = 1) writeonly buffer MortonBuffer { uint mortons[]; };  // of the cell & 1023
layout(std430, binding = 2) writeonly buffer JitterBuffer { vec4 jitters[]; };  // xyz: cellJitter

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  uvec4 v = inputs[i];
  mortons[i] = mortonEncode3(v.x & 1023u, v.y & 1023u, v.z & 1023u);
  jitters[i] = vec4(cellJitter(v.xyz, v.w, maxJitter), 0.0);
}
