// Parameters of the foam classification pass (raycast/glsl/FoamClassify.glsl), shared by C++
// (raycast/FoamTypes.h checks the layout) and GLSL; see core/GlslShared.h. std140: vec4s only.

struct FoamClassifyParams {
  uvec4 brick;   // x: cells per brick edge B; y: overlap n; z: sub-bricks per slot; w: sub-bricks
                 // of this batch (slots in the batch times z)
  vec4 sphere;   // x: radius in cells: a cell's neighbours are the cells whose centres lie within
                 // it; y: threshold: a set cell is foam when fewer than y times its neighbours are
                 // set; z: 1 = classify, 0 = keep the foam bits as uploaded (cells' kinds only);
                 // w: unused
};
