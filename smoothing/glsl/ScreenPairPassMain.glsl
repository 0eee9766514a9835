// Entry point of a two-output screen-space pass (ScreenDevice::runPair): one invocation per
// pixel writes the ScreenPair FS_KERNEL(pixel) returns, `first` to the output image and
// `second` to the second output. Included last, in place of ScreenPassMain.glsl.
layout(std430, binding = 7) writeonly buffer SecondOutput { vec4 secondOutputPixels[]; };

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= F.width || pixel.y >= F.height) return;
  uint i = pixel.y * F.width + pixel.x;
  ScreenPair values = FS_KERNEL(ivec2(pixel));
  outputPixels[i] = values.first;
  secondOutputPixels[i] = values.second;
}
