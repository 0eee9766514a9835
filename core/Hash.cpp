#include "core/Hash.h"

#include <xxhash.h>

namespace flipscope {

std::uint64_t checksum64(const void* data, std::size_t bytes) { return XXH3_64bits(data, bytes); }

}  // namespace flipscope
