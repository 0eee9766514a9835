// Adapter from the brick store to BrickSource (Reichl et al. 2014 §3.1).
#include "streaming/BrickSource.h"

#include <algorithm>

namespace flipscope {

bool BrickSource::hasFrame(int frame) const {
  const std::vector<int> all = frames();
  return std::binary_search(all.begin(), all.end(), frame);
}

std::shared_ptr<const DecodedBrick> StoreBrickSource::read(const BrickKey& key) {
  if (!mStore.hasFrame(key.frame)) return nullptr;
  std::shared_ptr<const FrameIndex> frame = mStore.frame(key.frame);
  const glm::uvec3 grid = mStore.header().brickGrid;
  if (key.coord.x >= grid.x || key.coord.y >= grid.y || key.coord.z >= grid.z) return nullptr;
  std::int64_t index = frame->octree.find(key.coord);
  if (index < 0) return nullptr;
  return std::make_shared<const DecodedBrick>(mStore.readBrick(*frame, std::uint32_t(index)));
}

}  // namespace flipscope
