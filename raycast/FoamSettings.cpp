#include "raycast/FoamSettings.h"

#include <cmath>

#include "core/Error.h"
#include "core/NumberText.h"

namespace flipscope {

FoamMode parseFoamMode(const std::string& text) {
  if (text == "volume") return FoamMode::Volume;
  if (text == "remove") return FoamMode::Remove;
  if (text == "keep") return FoamMode::Keep;
  throw InputError("--foam: unknown mode '" + text + "'; valid values: volume, remove, keep");
}

FoamSource parseFoamSource(const std::string& text) {
  if (text == "classify") return FoamSource::Classify;
  if (text == "kind") return FoamSource::Kind;
  if (text == "both") return FoamSource::Both;
  throw InputError("--foam-from: unknown source '" + text + "'; valid values: classify, kind, both");
}

const char* foamModeName(FoamMode mode) {
  switch (mode) {
    case FoamMode::Volume: return "volume";
    case FoamMode::Remove: return "remove";
    case FoamMode::Keep: return "keep";
  }
  return "unknown";
}

const char* foamSourceName(FoamSource source) {
  switch (source) {
    case FoamSource::Classify: return "classify";
    case FoamSource::Kind: return "kind";
    case FoamSource::Both: return "both";
  }
  return "unknown";
}

void validate(const FoamSettings& s) {
  if (!(s.threshold >= 0.0f && s.threshold <= 1.0f))
    throw InputError("--foam-threshold: must be a fraction in 0..1, got " + numberText(s.threshold));
  if (!(s.extinction >= 0.0f) || !std::isfinite(s.extinction))
    throw InputError("foam extinction must be 0 or positive, got " + numberText(s.extinction));
  if (!(s.step > 0.0f) || !std::isfinite(s.step))
    throw InputError("foam step must be a positive number of cells, got " + numberText(s.step));
  if (!(s.opacityStop > 0.0f && s.opacityStop <= 1.0f))
    throw InputError("foam opacity stop must be in (0, 1], got " + numberText(s.opacityStop));
}

}  // namespace flipscope
