// UpAxis: which world axis points up in a scene, as a particle file's conventions state it
// (Blender: +z; Houdini, RealFlow: +y), as a store records it (StoreHeader::upAxis) and as
// `--up` names it. It orients the default camera, the navigation's orbit and the sky.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <glm/vec3.hpp>

namespace flipscope {

/// The positive world axis that points up; Unknown: nobody said (renders then take +y).
/// The values are stored (store.fsh, version 6).
enum class UpAxis : std::uint32_t { Unknown = 0, X = 1, Y = 2, Z = 3 };

/// "unknown", "x", "y", "z".
constexpr std::string_view upAxisName(UpAxis axis) {
  switch (axis) {
    case UpAxis::X:
      return "x";
    case UpAxis::Y:
      return "y";
    case UpAxis::Z:
      return "z";
    case UpAxis::Unknown:
      break;
  }
  return "unknown";
}

/// "x", "y" or "z" as an axis; nullopt for anything else.
constexpr std::optional<UpAxis> parseUpAxisName(std::string_view name) {
  if (name == "x") return UpAxis::X;
  if (name == "y") return UpAxis::Y;
  if (name == "z") return UpAxis::Z;
  return std::nullopt;
}

/// The unit vector of `axis`; +y for Unknown (the convention of most DCCs and of OpenGL).
constexpr glm::dvec3 upAxisVector(UpAxis axis) {
  switch (axis) {
    case UpAxis::X:
      return {1, 0, 0};
    case UpAxis::Z:
      return {0, 0, 1};
    case UpAxis::Y:
    case UpAxis::Unknown:
      break;
  }
  return {0, 1, 0};
}

}  // namespace flipscope
