// libFuzzer target: the Maya .pdb reader (PdbParticles.cpp). Input format and body: FuzzTargets.h.
#include <cstddef>
#include <cstdint>
#include <span>

#include "FuzzTargets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  flipscope::fuzz::pdb(std::as_bytes(std::span(data, size)));
  return 0;
}
