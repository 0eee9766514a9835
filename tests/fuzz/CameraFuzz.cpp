// libFuzzer target: the camera JSON (parseCameraJson, as loadCamera reads it). Input format and body: FuzzTargets.h.
#include <cstddef>
#include <cstdint>
#include <span>

#include "FuzzTargets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  flipscope::fuzz::camera(std::as_bytes(std::span(data, size)));
  return 0;
}
