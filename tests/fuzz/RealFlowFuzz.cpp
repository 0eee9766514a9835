// libFuzzer target: the RealFlow .bin reader (RealFlowParticles.cpp). Input format and body: FuzzTargets.h.
#include <cstddef>
#include <cstdint>
#include <span>

#include "FuzzTargets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  flipscope::fuzz::realFlowBin(std::as_bytes(std::span(data, size)));
  return 0;
}
