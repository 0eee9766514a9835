// flipscope info: what a brick store holds, per frame, and --verify of every checksum.
// A store with no frames (an interrupted or failed convert) and a store missing a frame its
// frame table lists are refused: exit 3, or with --verify reported as damage, exit 1.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "core/Error.h"
#include "core/Progress.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/store/StoreInspection.h"
#include "tools/JsonOutput.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"

namespace flipscope::tools {
namespace {

struct InfoArgs {
  std::string store;
  bool json = false;
  bool verify = false;
};

void runInfo(const InfoArgs& a) {
  const BrickStore store = BrickStore::open(a.store);
  const StoreHeader& h = store.header();
  std::vector<FrameSummary> frames;
  std::vector<std::string> damage = checkFrameTable(store);
  if (!damage.empty() && !a.verify) {
    const std::vector<int> missing = store.missingFrames();
    if (missing.empty()) throw FileError(store.directory() / kStoreHeaderName, incompleteStoreReason());
    std::string reason = store.missingFrameReason(missing[0]);
    if (missing.size() > 1)
      reason +=
          " (and " + std::to_string(missing.size() - 1) + " more listed frame(s) missing; info --verify lists them)";
    throw FileError(store.framePath(missing[0]), reason);
  }
  if (a.verify)
    for (const auto& file : store.unlistedFrameFiles())
      std::fprintf(stderr, "note: %s: not in %s's frame table, so not part of the store\n", file.c_str(),
                   kStoreHeaderName);
  const std::vector<int> missing = store.missingFrames();
  for (int f : store.frames()) {
    if (std::binary_search(missing.begin(), missing.end(), f)) continue;  // reported above
    try {
      auto index = store.frame(f);
      frames.push_back(summarizeFrame(*index, h));
      if (a.verify) {
        auto errors = verifyFrame(store, *index);
        damage.insert(damage.end(), errors.begin(), errors.end());
      }
    } catch (const FileError& e) {
      if (!a.verify) throw;
      damage.push_back(e.what());
    }
  }
  FrameSummary total;
  for (const auto& s : frames) {
    total.particles += s.particles;
    total.bricks += s.bricks;
    total.occupiedCells += s.occupiedCells;
    total.storeBytes += s.storeBytes;
    total.skippedInvalid += s.skippedInvalid;
    total.skippedOutside += s.skippedOutside;
    for (std::size_t k = 0; k < kParticleKindCount; ++k) total.kindCells[k] += s.kindCells[k];
  }
  // Cells of each particle kind: null in a store without kinds.
  auto kindCells = [&](const FrameSummary& s) {
    if (!h.particleKinds) return nlohmann::json(nullptr);
    nlohmann::json cells;
    for (std::size_t k = 0; k < kParticleKindCount; ++k) cells[particleKindName(ParticleKind(k))] = s.kindCells[k];
    return cells;
  };
  // The attribute's range over the frames (store.fsh records it since version 4).
  std::optional<AttributeRange> range;
  if (a.verify) {
    try {
      range = store.attributeRange();
    } catch (const FileError&) {  // a damaged frame of a version 3 store: reported above
    }
  } else {
    range = store.attributeRange();
  }
  const bool attribute = h.attribute != AttributeKind::None;
  auto frameRange = [&](const FrameSummary& s) {
    return attribute && s.particles > 0 ? nlohmann::json::array({s.attributeMin, s.attributeMax})
                                        : nlohmann::json(nullptr);
  };
  const double cells = double(total.bricks) * h.cellsPerBrick();
  const double bpp = total.particles ? cells / double(total.particles) : 0;
  const double ratio = total.storeBytes ? 12.0 * double(total.particles) / double(total.storeBytes) : 0;

  if (a.json) {
    nlohmann::json j;
    j["store"] = a.store;
    j["version"] = h.version;
    j["brick_size"] = h.brickSize;
    j["cell_size"] = h.cellSize;
    // world units and cells of the store; null when the store does not know it
    j["particle_spacing"] = h.particleSpacing > 0 ? nlohmann::json(h.particleSpacing) : nlohmann::json(nullptr);
    j["particle_spacing_cells"] = h.particleSpacing > 0 ? nlohmann::json(spacingInCells(h)) : nlohmann::json(nullptr);
    j["origin"] = {h.origin.x, h.origin.y, h.origin.z};
    j["brick_grid"] = {h.brickGrid.x, h.brickGrid.y, h.brickGrid.z};
    j["attribute"] = attribute ? h.attributeName : "none";
    j["attribute_kind"] = attributeKindName(h.attribute);
    j["attribute_range"] = range ? nlohmann::json::array({range->min, range->max}) : nlohmann::json(nullptr);
    j["particle_kinds"] = h.particleKinds;
    // "x", "y" or "z"; null when the store records none (then render and view take y)
    j["up_axis"] = h.upAxis == UpAxis::Unknown ? nlohmann::json(nullptr) : nlohmann::json(upAxisName(h.upAxis));
    j["store_id"] = storeIdText(h.id);
    j["frames_missing"] = missing;
    j["frames"] = nlohmann::json::array();
    for (const auto& s : frames) {
      j["frames"].push_back({{"frame", s.frame},
                             {"particles", s.particles},
                             {"bricks", s.bricks},
                             {"occupied_cells", s.occupiedCells},
                             {"fill_rate", s.fillRate},
                             {"bits_per_particle", s.bitsPerParticle},
                             {"store_bytes", s.storeBytes},
                             {"ratio_to_raw", s.ratioToRaw},
                             {"skipped_invalid", s.skippedInvalid},
                             {"skipped_outside", s.skippedOutside},
                             {"attribute_range", frameRange(s)},
                             {"kind_cells", kindCells(s)}});
    }
    j["total"] = {{"particles", total.particles},
                  {"bricks", total.bricks},
                  {"bits_per_particle", bpp},
                  {"store_bytes", total.storeBytes},
                  {"ratio_to_raw", ratio},
                  {"kind_cells", kindCells(total)}};
    if (a.verify) {
      j["verified"] = damage.empty();
      j["damage"] = damage;
    }
    printJson(j);
  } else {
    std::printf("store      %s (version %u, id %s)\n", a.store.c_str(), h.version, storeIdText(h.id).c_str());
    std::printf("domain     origin (%g, %g, %g), cell size %g, %ux%ux%u bricks of %u^3 cells\n", h.origin.x, h.origin.y,
                h.origin.z, h.cellSize, h.brickGrid.x, h.brickGrid.y, h.brickGrid.z, h.brickSize);
    if (h.particleSpacing > 0)
      std::printf("spacing    particle spacing %g = %.2f cells of %g\n", h.particleSpacing, spacingInCells(h),
                  h.cellSize);
    else
      std::printf("spacing    particle spacing unknown (cell size %g)\n", h.cellSize);
    if (range)
      std::printf("attribute  %s, %g to %g over the frames\n", describeAttribute(h).c_str(), range->min, range->max);
    else
      std::printf("attribute  %s\n", describeAttribute(h).c_str());
    if (h.upAxis != UpAxis::Unknown)
      std::printf("up axis    %s\n", std::string(upAxisName(h.upAxis)).c_str());
    else
      std::printf("up axis    not recorded (render and view take y unless given --up)\n");
    if (h.particleKinds)
      std::printf("kinds      a particle kind per cell; cells over the frames: %s\n\n",
                  describeKindCells(total.kindCells).c_str());
    else
      std::printf("kinds      none (every cell liquid)\n\n");
    std::printf("%7s %14s %9s %8s %10s %12s %9s\n", "frame", "particles", "bricks", "fill", "bits/part", "bytes",
                "raw/store");
    for (const auto& s : frames)
      std::printf("%7d %14llu %9u %7.2f%% %10.2f %12llu %8.1fx\n", s.frame, (unsigned long long)s.particles, s.bricks,
                  100 * s.fillRate, s.bitsPerParticle, (unsigned long long)s.storeBytes, s.ratioToRaw);
    std::printf("%7s %14llu %9u %7.2f%% %10.2f %12llu %8.1fx\n", "total", (unsigned long long)total.particles,
                total.bricks, cells > 0 ? 100 * double(total.occupiedCells) / cells : 0.0, bpp,
                (unsigned long long)total.storeBytes, ratio);
    if (total.skippedInvalid || total.skippedOutside)
      std::printf("skipped at conversion: %llu NaN/Inf, %llu outside the domain\n",
                  (unsigned long long)total.skippedInvalid, (unsigned long long)total.skippedOutside);
    if (a.verify && damage.empty())
      std::printf("verify: the %zu frames %s lists are all present and every checksum is intact\n", frames.size(),
                  kStoreHeaderName);
  }
  if (!damage.empty()) {
    for (const auto& d : damage) std::fprintf(stderr, "damaged: %s\n", d.c_str());
    throw CommandFailed("verify: " + std::to_string(damage.size()) + " damaged or missing brick(s) or frame(s) in " +
                        a.store);
  }
}

}  // namespace

void addInfoCommand(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* cmd = app.add_subcommand("info", "What a brick store holds: frames, particles, bricks, bits per particle");
  cmd->add_option("store", args->store, "Brick store directory")->required();
  cmd->add_flag("--json", args->json, "Machine-readable output");
  cmd->add_flag("--verify", args->verify, "Read every brick and check every checksum; exit 1 on damage");
  cmd->callback([args] { runInfo(*args); });
}

}  // namespace flipscope::tools
