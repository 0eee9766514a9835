// A small Maya .pdb writer for the reader tests: the 32-bit layout (as partio writes it) or the
// 64-bit one (as a 64-bit build of Maya's structures would), any channels. Every value of
// particle p is derived from p, the channel and the component, so a reader that takes a value
// from the wrong place is caught.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace flipscope::testing {

struct PdbChannelSpec {
  std::string name;
  int type = 1;       ///< 1 vector, 2 real, 3 long, 4 char, 5 pointer
  int components = 3; ///< values a particle (vector: 3; pointer: 8-byte values)
};

/// The value of channel `channel`, component c, of particle p (as stored, before its type).
inline double pdbValue(std::size_t p, std::size_t channel, int c) {
  return double(p % 100) * 0.5 + double(channel) * 10 + c;
}

inline std::string makePdb(const std::vector<PdbChannelSpec>& channels, std::size_t count, bool pointers64 = false) {
  std::string out;
  auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  auto pointer = [&] { out.append(pointers64 ? 8 : 4, '\0'); };
  put(std::int32_t(670));
  put(std::uint16_t(1));  // swap
  out.append(2, '\0');    // alignment
  put(1.0f);              // version
  put(0.25f);             // time
  put(std::uint32_t(count));
  put(std::uint32_t(channels.size()));
  out.append(32, '\0');  // padding
  pointer();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const PdbChannelSpec& c = channels[i];
    const std::uint32_t bytes = c.type == 4 ? std::uint32_t(c.components)
                                : c.type == 5 ? 8u * std::uint32_t(c.components)
                                              : 4u * std::uint32_t(c.components);
    out += "c";  // I/O header: magic, alignment, swap, encoding, type
    out += '\0';
    put(std::uint16_t(1));
    out.append(2, '\0');
    pointer();  // the channel: name
    put(std::int32_t(c.type));
    put(std::uint32_t(0));                  // size
    put(std::uint32_t(0));                  // active start
    put(std::uint32_t(count ? count - 1 : 0));  // active end
    out.append(2, '\0');                    // hide, disconnect
    out.append(pointers64 ? 6 : 2, '\0');   // alignment
    pointer();                              // data
    pointer();                              // link
    pointer();                              // next
    out += c.name;
    out += '\0';
    put(std::int32_t(c.type));  // data header
    put(bytes);
    put(std::uint32_t(count));  // block size
    put(std::int32_t(1));       // blocks
    pointer();
    for (std::size_t p = 0; p < count; ++p)
      for (int k = 0; k < c.components; ++k) {
        const double v = pdbValue(p, i, k);
        if (c.type == 1 || c.type == 2) put(float(v));
        if (c.type == 3) put(std::int32_t(v * 2));
        if (c.type == 4) put(std::int8_t(int(v) % 100));
        if (c.type == 5) put(std::uint64_t(0x1000 + p));
      }
  }
  return out;
}

}  // namespace flipscope::testing
