// What a render does with foam (Reichl et al. 2014 §3.5): which cells count as foam, and whether
// foam is rendered as a volume, removed, or kept as spheres like the rest. `render --foam`,
// `--foam-from`, `--foam-threshold`.
#pragma once

#include <string>

namespace flipscope {

/// volume (default): foam cells are no spheres; the ray-caster accumulates them as a volume in
/// front of the surface. remove: foam cells are dropped, exposing the surface. keep: no foam
/// (every cell is a sphere; no classification).
enum class FoamMode { Volume, Remove, Keep };
/// classify: cells with few set neighbours (§3.5); kind: cells whose stored particle kind is foam
/// or spray (convert's kinds, preprocess/store/ParticleKind.h); both (default): either.
enum class FoamSource { Classify, Kind, Both };

struct FoamSettings {
  FoamMode mode = FoamMode::Volume;
  FoamSource source = FoamSource::Both;
  /// A set cell is foam when fewer than this fraction of the cells within the sphere radius of it
  /// are set (§3.5: "less than 20%"). In [0, 1].
  float threshold = 0.2f;
  /// Volumetric foam: extinction per cell at foam density 1 (a 4^3 block full of foam cells). A
  /// lone foam cell (density 1/64 over the 4 cells of its block) is then 3% opaque, a block a
  /// quarter full of foam 39%: the cells the classification finds scattered through a thin FLIP
  /// sheet give a faint haze, the spray clouds white foam.
  float extinction = 0.5f;
  float step = 1.0f;          ///< march step in cells (the density varies over 4^3 blocks)
  float opacityStop = 0.95f;  ///< the ray ends in foam this opaque (§3.5)
  /// Stores with particle kinds: bubbles lie inside the liquid and are not rendered (--bubbles
  /// hide, the default); shown, they are particles like the liquid's.
  bool hideBubbles = true;

  bool classifies() const { return mode != FoamMode::Keep && source != FoamSource::Kind; }
  bool usesKinds() const { return mode != FoamMode::Keep && source != FoamSource::Classify; }
};

/// "volume", "remove", "keep". Throws InputError naming --foam and the valid values.
FoamMode parseFoamMode(const std::string& text);
/// "classify", "kind", "both". Throws InputError naming --foam-from and the valid values.
FoamSource parseFoamSource(const std::string& text);
const char* foamModeName(FoamMode mode);
const char* foamSourceName(FoamSource source);
/// Throws InputError naming the option that is out of range (--foam-threshold outside [0, 1]).
void validate(const FoamSettings& settings);

}  // namespace flipscope
