// What the two classic Houdini geometry readers share (ClassicBgeo.cpp: binary "BgeoV",
// ClassicBgeoAscii.cpp: ASCII "PGEOMETRY"): the attribute dictionary of version 5 and which of
// its attributes become velocities and attribute columns. Private to flipscope::particles.
//
// The classic format (Houdini 5 to 11, documented by Side Effects in GPD.txt, "Public Domain
// Geometry Library, Version 5"; the binary form is big-endian): a header of counts, the point
// attribute dictionary (name, size, type, default), the points (x y z w, then each attribute's
// values), then vertex and primitive dictionaries, the primitives, the groups, the detail
// attributes and an "extra" section. Particles are the points; w (the NURBS weight) is dropped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope::detail::houdini {

/// Attribute storage types of GPD version 5.
enum class ClassicType : std::int32_t { Float = 0, Int = 1, String = 2, Mixed = 3, Index = 4, Vector = 5 };

/// "float", "int", "string", "mixed", "index", "vector", or the number.
std::string classicTypeName(std::int32_t type);

struct ClassicAttribute {
  std::string name;
  int size = 1;  ///< components
  ClassicType type = ClassicType::Float;
  std::size_t offset = 0;  ///< bytes from the start of a binary point record; values before it in ASCII
};

/// The point attributes a reader exposes: the numeric ones (float, int, vector; index
/// attributes hold string indices and are skipped) as attributes(), `v` (3 floats) as velocity.
struct ClassicPlan {
  std::vector<AttributeDesc> exposed;      ///< attributes()
  std::vector<std::size_t> exposedSource;  ///< index into the point dictionary, one per exposed
  std::optional<std::size_t> velocity;     ///< index into the point dictionary
};
ClassicPlan planClassicAttributes(const std::vector<ClassicAttribute>& point);

std::unique_ptr<ParticleSource> openClassicBgeoAscii(InputFile file, const ReadOptions& options);

}  // namespace flipscope::detail::houdini
