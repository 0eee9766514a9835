// A small RealFlow particle .bin writer for the reader tests: any version from 1 to 12 (the
// record fields of that version), a chosen trailing section. Every value of particle p is
// derived from p and the field, so a reader that puts a field at the wrong offset is caught.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

namespace flipscope::testing {

/// The float stored in float field `field` (0 position ... ), component c, of particle p.
inline float realFlowValue(std::size_t p, int field, int c) {
  return float(p) * 0.5f + float(field) * 100.f + float(c);
}

/// Trailing sections as different writers make them.
inline const std::string kRealFlowTail10("\0\0\0\0\0\1\0\0\0\0", 10);  // RealFlow itself
inline const std::string kRealFlowTail6("\0\0\0\0\0\0", 6);            // count, RF4 flag, RF5 flag
inline const std::string kRealFlowTail5("\0\0\0\0\0", 5);              // Krakatoa (version 9)

inline std::string makeRealFlowBin(int version, std::size_t count, const std::string& tail = kRealFlowTail10,
                                   const std::string& fluid = "Square01") {
  std::string out;
  auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  put(std::uint32_t(0x00FABADA));
  char name[250] = {};
  std::memcpy(name, fluid.data(), fluid.size());
  out.append(name, 250);
  put(std::int16_t(version));
  put(1.f);               // scale
  put(std::int32_t(8));   // fluid type
  put(0.5f);              // elapsed time
  put(std::int32_t(12));  // frame
  put(std::int32_t(24));  // fps
  put(std::int32_t(count));
  put(0.1f);                                  // radius
  for (int i = 0; i < 9; ++i) put(float(i));  // pressure, speed, temperature ranges
  if (version >= 7)
    for (int i = 0; i < 9; ++i) put(i >= 6 ? 1.f : 0.f);  // emitter position, rotation, scale
  for (std::size_t p = 0; p < count; ++p) {
    int field = 0;
    auto vec = [&](int f) {
      for (int c = 0; c < 3; ++c) put(realFlowValue(p, f, c));
    };
    vec(field++);                  // position
    vec(field++);                  // velocity
    vec(field++);                  // force
    if (version >= 9) vec(field);  // vorticity
    ++field;
    if (version >= 3) vec(field);  // normal
    ++field;
    if (version >= 4) put(std::int32_t(p % 30));  // neighbours
    ++field;
    if (version >= 5) {
      vec(field);                // texture
      put(std::int16_t(p % 3));  // info bits
    }
    ++field;
    for (int scalar = 0; scalar < 7; ++scalar) put(realFlowValue(p, field + scalar, 0));  // age ... temperature
    if (version >= 12)
      put(std::int64_t(p) * 1000 + 1);
    else
      put(std::int32_t(p) + 1);
  }
  out += tail;
  return out;
}

}  // namespace flipscope::testing
