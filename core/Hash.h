// Checksums for stored data: XXH3-64 from the xxHash library (Debian libxxhash-dev), chosen
// for speed (several GB/s a core) so that `info --verify` runs at disk speed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace flipscope {

std::uint64_t checksum64(const void* data, std::size_t bytes);
inline std::uint64_t checksum64(std::span<const std::byte> bytes) { return checksum64(bytes.data(), bytes.size()); }

}  // namespace flipscope
