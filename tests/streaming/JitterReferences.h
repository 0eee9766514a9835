// Reference values of tea() and cellJitter() (streaming/glsl/Jitter.glsl), computed by the C++
// side. Shared by the CPU test (tests/streaming/JitterTest.cpp) and the GPU test, which must
// reproduce them bit for bit from a compute shader: #include "streaming/JitterReferences.h"
// from any test folder (tests/ is on the include path).
#pragma once

#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace flipscope::testing {

struct TeaReference {
  glm::uvec2 input;
  std::uint32_t rounds;
  glm::uvec2 output;
};

inline const TeaReference kTeaReferences[] = {
    {{0x00000000u, 0x00000000u}, 4u, {0x5df5f2bfu, 0x54ce08bau}},
    {{0x00000001u, 0x00000000u}, 4u, {0xc09848f2u, 0x8562613fu}},
    {{0x12345678u, 0x9abcdef0u}, 4u, {0x74e1596eu, 0xa34a3b8du}},
    {{0xdeadbeefu, 0x00000007u}, 8u, {0x7d9e4fb7u, 0xe0c271cau}},
    {{0x0000002au, 0x00000003u}, 1u, {0xf57776aeu, 0x10e823ecu}},
};

struct JitterReference {
  glm::uvec3 cell;
  std::uint32_t timeStep;
  float maxJitter;
  glm::vec3 offset;
};

inline const JitterReference kJitterReferences[] = {
    {{0u, 0u, 0u}, 0u, 1.0f, {0.623291254f, 0.641715765f, 0.646440148f}},
    {{1u, 2u, 3u}, 0u, 1.0f, {0.0185861588f, 0.949312449f, 0.293042779f}},
    {{1u, 2u, 3u}, 1u, 1.0f, {0.897917986f, -0.91811049f, 0.370374918f}},
    {{1023u, 1023u, 1023u}, 7u, 0.5f, {-0.152350783f, 0.432823122f, -0.473975658f}},
    {{1024u, 5u, 9u}, 3u, 2.0f, {-1.17360759f, 1.54734778f, 1.12408018f}},
    {{131071u, 65536u, 4097u}, 250u, 1.5f, {-1.41763139f, -1.20311117f, 0.591141522f}},
    {{300u, 17u, 999u}, 100000u, 0.25f, {0.100587428f, 0.249488026f, 0.107705474f}},
};

}  // namespace flipscope::testing
