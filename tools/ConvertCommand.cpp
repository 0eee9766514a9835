// flipscope convert: particle caches -> brick store (preprocess/Convert.h).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <optional>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "core/ProcessMemory.h"
#include "preprocess/Convert.h"
#include "preprocess/particles/InputSequence.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "tools/CliChecks.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"

namespace flipscope::tools {
namespace {

struct ConvertArgs {
  std::vector<std::string> inputs;
  std::string store;
  std::string frames;
  std::vector<std::string> grids;
  double cellSize = 0;
  std::uint32_t resolution = 0;  ///< 0: not given
  std::optional<double> particleSpacing;
  std::uint32_t brickSize = 64;
  std::string domain;
  std::string mem = "4G";
  std::string attribute = "auto";
  std::string kindAttribute = "auto";
  std::string up = "auto";
  int zstdLevel = 1;
  std::string scratch;
  bool append = false;
  bool prepare = false;
  bool quiet = false;
};

void runConvert(const ConvertArgs& a) {
  // SIGINT, SIGTERM and SIGHUP remove the temporary and spill files, then end the process.
  installCleanupSignalHandlers();
  ConvertOptions options;
  if (a.cellSize != 0) options.cellSize = a.cellSize;
  if (a.resolution != 0) options.resolution = a.resolution;
  options.particleSpacing = a.particleSpacing;
  options.brickSize = a.brickSize;
  if (!a.domain.empty()) options.domain = parseBox("--domain", a.domain);
  options.memoryBudget = parseBytes("--mem", a.mem);
  if (a.attribute != "auto") options.attribute = a.attribute;
  if (a.kindAttribute != "auto") options.kindAttribute = a.kindAttribute;
  options.upAxis = parseUpAxis("--up", a.up);
  options.zstdLevel = a.zstdLevel;
  options.scratchDir = a.scratch;
  options.append = a.append;
  options.prepareOnly = a.prepare;
  options.read.grids = a.grids;
  options.progress = a.quiet ? Progress::Mode::Silent : Progress::Mode::Auto;

  std::optional<FrameRange> range;
  if (!a.frames.empty()) range = parseFrameRange(a.frames);
  const auto inputs = expandInputs(a.inputs, range);
  const ConvertReport report = convert(inputs, a.store, options);
  for (const auto& warning : report.warnings) std::fprintf(stderr, "warning: %s\n", warning.c_str());

  if (a.quiet) return;
  const StoreHeader& h = report.header;
  if (a.prepare) {
    std::printf("store %s prepared: cell size %g (%s), bricks of %u^3, grid %ux%ux%u bricks, attribute %s, no "
                "frames yet\n",
                a.store.c_str(), h.cellSize, report.cellSizeOrigin.c_str(), h.brickSize, h.brickGrid.x, h.brickGrid.y,
                h.brickGrid.z, describeAttribute(h).c_str());
    return;
  }
  std::printf("store %s: cell size %g (%s), bricks of %u^3, grid %ux%ux%u bricks, attribute %s%s\n", a.store.c_str(),
              h.cellSize, report.cellSizeOrigin.c_str(), h.brickSize, h.brickGrid.x, h.brickGrid.y, h.brickGrid.z,
              describeAttribute(h).c_str(), h.particleKinds ? ", particle kinds" : "");
  if (h.particleSpacing > 0)
    std::printf("particle spacing %g (%.2f cells), from %s\n", h.particleSpacing, h.particleSpacing / h.cellSize,
                report.spacingOrigin.c_str());
  else
    std::printf("particle spacing unknown (%s)\n", report.spacingOrigin.c_str());
  std::printf("up axis %s (%s)\n", std::string(upAxisName(h.upAxis)).c_str(), report.upAxisOrigin.c_str());
  for (const auto& f : report.frames) {
    std::printf("  frame %d: %llu particles, %u bricks, %s bytes, %.2f s", f.frame,
                (unsigned long long)f.stats.particles, f.bricks, Progress::humanCount(double(f.storeBytes)).c_str(),
                f.seconds);
    if (f.spillBuckets)
      std::printf(" (out of core: %s bytes spilled to %u buckets)", Progress::humanCount(double(f.spillBytes)).c_str(),
                  f.spillBuckets);
    if (h.attribute != AttributeKind::None && f.stats.particles > 0)
      std::printf("; %s %g to %g", h.attributeName.c_str(), f.stats.attributeMin, f.stats.attributeMax);
    if (h.particleKinds) std::printf("; cells %s", describeKindCells(f.stats.kindCells).c_str());
    if (f.stats.skippedInvalid || f.stats.skippedOutside)
      std::printf("; skipped %llu NaN/Inf and %llu outside the domain", (unsigned long long)f.stats.skippedInvalid,
                  (unsigned long long)f.stats.skippedOutside);
    std::printf("\n");
  }
  std::printf("peak memory %.0f MiB (--mem %s)\n", double(peakResidentBytes()) / (1 << 20), a.mem.c_str());
}

}  // namespace

void addConvertCommand(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd = app.add_subcommand(
      "convert", "Bin particle caches (" + supportedExtensions() + "; files, sequences, patterns) into a brick store");
  cmd->add_option("inputs", args->inputs,
                  "Input files or patterns (name_####.vdb, %04d, {}); several per frame merge into one frame")
      ->required();
  cmd->add_option("-o,--output", args->store, "Brick store directory (created, or appended to)")->required();
  cmd->add_option("--frames", args->frames, "Frame range A-B for patterns (default: every frame found)");
  cmd->add_option("--grid", args->grids, "VDB: PointDataGrid names to read (default: all)");
  auto* cell = cmd->add_option("--cell-size", args->cellSize, "Cell size in world units (default: see --resolution)")
                   ->check(positiveNumber());
  cmd->add_option("--resolution", args->resolution,
                  "Cells along the longest domain axis (default: one cell per particle spacing, measured on the "
                  "first frame; 1024 when it cannot be)")
      ->check(positiveCount())
      ->excludes(cell);
  cmd->add_option("--brick-size", args->brickSize, "Cells per brick edge")
      ->check(CLI::IsMember({32, 64, 128}))
      ->capture_default_str();
  cmd->add_option("--particle-spacing", args->particleSpacing,
                  "Particle spacing in world units, e.g. the simulation's particle separation (default: measured "
                  "on the first frame; with --domain too, convert reads each frame once; 0: unknown, not measured)")
      ->check(nonNegativeNumber());
  cmd->add_option("--domain", args->domain, "x0,y0,z0,x1,y1,z1 in world units (default: bounds of the data)");
  cmd->add_option("--mem", args->mem, "Memory budget, e.g. 512M, 8G")->capture_default_str();
  cmd->add_option("--attribute", args->attribute,
                  "Per-particle attribute to store (16 bits): auto (speed when the inputs have velocities), none, "
                  "speed, or the name of an attribute of the inputs (a vector one by its length)")
      ->capture_default_str();
  cmd->add_option("--kind-attribute", args->kindAttribute,
                  "Integer attribute holding each particle's type as Mantaflow's flags (2 spray, 4 bubble, 8 foam, "
                  "else liquid), stored as a kind per cell: auto (Blender Mantaflow's U of particles_secondary), "
                  "none, or an attribute name; inputs without it are liquid")
      ->capture_default_str();
  cmd->add_option("--up", args->up,
                  "The scene's up axis the store records, which render and view frame with: auto (what the input "
                  "files' conventions say: z for Blender, y for Houdini, RealFlow and Maya), x, y or z")
      ->capture_default_str();
  cmd->add_option("--zstd-level", args->zstdLevel, "zstd level of brick payloads")
      ->check(CLI::Range(-5, 19))
      ->capture_default_str();
  cmd->add_option("--scratch", args->scratch, "Directory for spill files (default: the store)");
  auto* prepare = cmd->add_flag("--prepare", args->prepare,
                                "Write only the store header (domain, cell size, attribute), for converts that then "
                                "--append frames at the same time (what farm convert does)");
  cmd->add_flag("--append", args->append,
                "Add the frames to the existing store -o, keeping its header (also one made by --prepare); "
                "any number of converts may add frames to one store at once")
      ->excludes(prepare);
  cmd->add_flag("-q,--quiet", args->quiet, "No progress and no summary");
  cmd->callback([args] { runConvert(*args); });
}

}  // namespace flipscope::tools
