// A small writer of Houdini classic geometry (GPD version 5) for the reader tests, in both
// forms: binary "BgeoV" (big-endian) and ASCII "PGEOMETRY V5". Points with any point
// attributes (float, int, vector, index), optionally one particle-system primitive over all the
// points with a primitive attribute, optionally detail attributes; the extra section ends it.
#pragma once

#include <bit>
#include <cstdint>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace flipscope::testing {

struct BgeoAttributeSpec {
  std::string name;
  int type = 0;  ///< 0 float, 1 int, 4 index, 5 vector
  int size = 1;
  std::vector<std::string> strings;  ///< an index attribute's strings
};

struct BgeoWriteOptions {
  bool particlePrimitive = false;  ///< one "Part" primitive over every point, with an index primitive attribute
  bool detailAttributes = false;   ///< two int detail attributes
};

/// value(point, attribute, component): the attribute values; position(point, axis): x y z.
using BgeoValue = std::function<double(std::size_t, std::size_t, int)>;
using BgeoPosition = std::function<float(std::size_t, int)>;

inline std::string makeClassicBgeo(std::size_t count, const std::vector<BgeoAttributeSpec>& attributes,
                                   const BgeoPosition& position, const BgeoValue& value,
                                   const BgeoWriteOptions& options = {}) {
  std::string out = "BgeoV";
  auto u16 = [&](std::uint16_t v) {
    v = __builtin_bswap16(v);
    out.append(reinterpret_cast<const char*>(&v), 2);
  };
  auto i32 = [&](std::int32_t v) {
    const std::uint32_t b = __builtin_bswap32(std::uint32_t(v));
    out.append(reinterpret_cast<const char*>(&b), 4);
  };
  auto f32 = [&](float v) { i32(std::int32_t(std::bit_cast<std::uint32_t>(v))); };
  auto str = [&](const std::string& s) {
    u16(std::uint16_t(s.size()));
    out += s;
  };
  i32(5);
  i32(std::int32_t(count));
  i32(options.particlePrimitive ? 1 : 0);
  i32(0);
  i32(0);
  i32(std::int32_t(attributes.size()));
  i32(0);
  i32(options.particlePrimitive ? 1 : 0);
  i32(options.detailAttributes ? 2 : 0);
  for (const auto& a : attributes) {
    str(a.name);
    u16(std::uint16_t(a.size));
    i32(a.type);
    if (a.type == 4) {
      i32(std::int32_t(a.strings.size()));
      for (const auto& s : a.strings) str(s);
    } else {
      for (int c = 0; c < a.size; ++c) a.type == 1 ? i32(0) : f32(0.f);
    }
  }
  for (std::size_t p = 0; p < count; ++p) {
    for (int c = 0; c < 3; ++c) f32(position(p, c));
    f32(1.f);
    for (std::size_t i = 0; i < attributes.size(); ++i)
      for (int c = 0; c < attributes[i].size; ++c) {
        const double v = value(p, i, c);
        attributes[i].type == 1 || attributes[i].type == 4 ? i32(std::int32_t(v)) : f32(float(v));
      }
  }
  if (options.particlePrimitive) {
    str("generator");
    u16(1);
    i32(4);
    i32(1);
    str("papi");
    i32(0x8000);
    i32(std::int32_t(count));
    for (std::size_t p = 0; p < count; ++p) count <= 0xffff ? u16(std::uint16_t(p)) : i32(std::int32_t(p));
    i32(0);
  }
  if (options.detailAttributes) {
    for (const char* name : {"fixed1", "fixed2"}) {
      str(name);
      u16(1);
      i32(1);
      i32(0);
    }
    i32(7);
    i32(8);
  }
  out += '\0';
  out += '\xff';
  return out;
}

inline std::string makeClassicGeo(std::size_t count, const std::vector<BgeoAttributeSpec>& attributes,
                                  const BgeoPosition& position, const BgeoValue& value,
                                  const BgeoWriteOptions& options = {}) {
  std::ostringstream out;
  out.precision(9);
  out << "PGEOMETRY V5\nNPoints " << count << " NPrims " << (options.particlePrimitive ? 1 : 0)
      << "\nNPointGroups 0 NPrimGroups 0\nNPointAttrib " << attributes.size() << " NVertexAttrib 0 NPrimAttrib "
      << (options.particlePrimitive ? 1 : 0) << " NAttrib " << (options.detailAttributes ? 2 : 0) << "\n";
  if (!attributes.empty()) {
    out << "PointAttrib\n";
    for (const auto& a : attributes) {
      out << a.name << " " << a.size << " ";
      if (a.type == 4) {
        out << "index " << a.strings.size();
        for (const auto& s : a.strings) out << " " << s;
      } else {
        out << (a.type == 0 ? "float" : a.type == 1 ? "int" : "vector");
        for (int c = 0; c < a.size; ++c) out << " 0";
      }
      out << "\n";
    }
  }
  for (std::size_t p = 0; p < count; ++p) {
    out << position(p, 0) << " " << position(p, 1) << " " << position(p, 2) << " 1";
    if (!attributes.empty()) {
      out << " (";
      const char* separator = "";
      for (std::size_t i = 0; i < attributes.size(); ++i)
        for (int c = 0; c < attributes[i].size; ++c) {
          out << separator << value(p, i, c);
          separator = c + 1 < attributes[i].size ? " " : "\t";
        }
      out << ")";
    }
    out << "\n";
  }
  if (options.particlePrimitive) {
    out << "PrimitiveAttrib\ngenerator 1 index 1 papi\nPart " << count;
    for (std::size_t p = 0; p < count; ++p) out << " " << p;
    out << " [0]\n";
  }
  if (options.detailAttributes) out << "DetailAttrib\nfixed1 1 int 0\nfixed2 1 int 0\n (7 8)\n";
  out << "beginExtra\nendExtra\n";
  return out.str();
}

}  // namespace flipscope::testing
