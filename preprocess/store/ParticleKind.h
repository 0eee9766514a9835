// ParticleKind: what a cell of a brick holds, liquid or one of the secondary particles of a
// FLIP solver (foam, spray, bubbles), for stores with StoreHeader::particleKinds.
#pragma once

#include <cstdint>

namespace flipscope {

/// The kind of a cell. The value order is the precedence inside one cell: a cell's kind is the
/// smallest kind among its particles (any liquid particle makes it liquid, foam beats spray,
/// bubble only when it holds nothing else). Stored as these values (BrickStore.h).
enum class ParticleKind : std::uint8_t { Liquid = 0, Foam = 1, Spray = 2, Bubble = 3 };
inline constexpr std::uint32_t kParticleKindCount = 4;

/// "liquid", "foam", "spray", "bubble".
constexpr const char* particleKindName(ParticleKind kind) {
  switch (kind) {
    case ParticleKind::Liquid: return "liquid";
    case ParticleKind::Foam: return "foam";
    case ParticleKind::Spray: return "spray";
    case ParticleKind::Bubble: return "bubble";
  }
  return "unknown";
}

/// Mantaflow's particle type flags (ParticleBase::PSPRAY = 2, PBUBBLE = 4, PFOAM = 8, as Blender
/// writes them into the int32 attribute `U` of its secondary particles): exactly 2 is spray, 4
/// bubble, 8 foam; anything else (0, 1 = FLIP fluid, combined or unknown flags) is liquid.
constexpr ParticleKind fromMantaflowType(std::int32_t flags) {
  switch (flags) {
    case 2: return ParticleKind::Spray;
    case 4: return ParticleKind::Bubble;
    case 8: return ParticleKind::Foam;
    default: return ParticleKind::Liquid;
  }
}

}  // namespace flipscope
