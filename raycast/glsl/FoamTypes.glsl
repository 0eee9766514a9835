// Parameters of the foam classification pass (raycast/glsl/FoamClassify.glsl), shared by C++
// (raycast/FoamTypes.h checks the layout) and GLSL; see core/GlslShared.h. std140: scalars in groups of four.

struct FoamClassifyParams {
  uint brickSize;         // cells per brick edge B
  uint overlap;           // n: cells each stored bit-brick reaches beyond its brick on every side
  uint subBricksPerSlot;
  uint batchSubBricks;    // sub-bricks of this batch: the batch's slots times subBricksPerSlot
  float radius;           // in cells: a cell's neighbours are the cells whose centres lie within it
  float threshold;        // a set cell is foam when fewer than threshold times its neighbours are set
  uint classify;          // 1: classify; 0: keep the foam bits as uploaded (the cells' kinds only)
  uint unused0;
};
