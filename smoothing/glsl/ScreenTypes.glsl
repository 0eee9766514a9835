// The frame every screen-space pass sees (Reichl et al. 2014 §3.3, Fig. 3: smoothing, normal
// reconstruction and shading run on the ray-caster's images). Shared by C++
// (smoothing/ScreenTypes.h, which checks every offset) and GLSL; see core/GlslShared.h for the
// rules. A std140 uniform block: 16-byte vectors, then scalars in groups of four.
//
// Images are arrays of vec4, row 0 at the top, pixel (x, y) at y * width + x. Depth is linear
// camera depth in world units (distance along the view direction), as the ray-caster writes it.

struct ScreenFrame {
  vec4 forward;          // xyz: unit view direction (world); w: unused
  vec4 right;            // xyz: unit right vector (world); w: unused
  vec4 up;               // xyz: unit up vector of the image (world); w: unused
  vec4 worldUp;          // xyz: unit up axis of the scene (world), for the environment; w: unused
  uint width;            // pixels
  uint height;           // pixels
  float tanHalfFovY;     // tan(vertical fov / 2)
  float aspect;          // width / height
  float focalPixels;     // image height / (2 tan(fov / 2)): pixels per world unit at depth 1
  float particleRadius;  // sphere radius in world units
  float cellSize;        // world units
  float unused0;
};

// What the kernel of a two-output pass returns (ScreenDevice::runPair): `first` goes to its
// output, `second` to its second output.
struct ScreenPair {
  vec4 first;
  vec4 second;
};
