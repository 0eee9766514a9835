// Entry point of a screen-space pass: one invocation per pixel writes FS_KERNEL(pixel) (a
// function `vec4 k(ivec2)`, chosen by the host with a #define) to the output image.
void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= F.width || pixel.y >= F.height) return;
  outputPixels[pixel.y * F.width + pixel.x] = FS_KERNEL(ivec2(pixel));
}
