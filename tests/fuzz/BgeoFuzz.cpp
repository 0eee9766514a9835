// libFuzzer target: the Houdini JSON geometry reader (.bgeo binary and .geo ASCII, recognised by
// content). Input format and body: FuzzTargets.h.
#include <cstddef>
#include <cstdint>
#include <span>

#include "FuzzTargets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  flipscope::fuzz::bgeo(std::as_bytes(std::span(data, size)));
  return 0;
}
