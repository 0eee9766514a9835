// `flipscope synth`: writes procedural FLIP-like frames (preprocess/SynthFluid.h) in any writable
// particle format (raw, PLY, VDB, Houdini bgeo/geo/bgeo.sc, PRT, VTK), chunk by chunk;
// generation of the next chunk overlaps writing of the current one.
#include <CLI/CLI.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <string>

#include "core/Error.h"
#include "core/Progress.h"
#include "preprocess/SynthFluid.h"
#include "preprocess/particles/InputSequence.h"
#include "preprocess/particles/ParticleWriter.h"
#include "tools/CliChecks.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"

namespace flipscope::tools {

namespace {

constexpr std::uint64_t kMinParticles = 1'000;
constexpr std::uint64_t kMaxParticles = 1'000'000'000;
constexpr std::uint64_t kMaxVdbParticles = 50'000'000;  // the VDB writer holds a frame in memory
constexpr std::size_t kChunkParticles = 1 << 20;

/// --particles: a count from 1 k to 1 G (suffixes k, M, G).
std::uint64_t parseParticleCount(const std::string& text) {
  std::uint64_t count = parseCount("--particles", text);
  if (count < kMinParticles || count > kMaxParticles)
    throw InputError("--particles: expected a count from 1k to 1G, got '" + text + "'");
  return count;
}

struct SynthArguments {
  std::string output;
  std::string particles = "1M";
  std::string frames = "0";
  std::uint64_t seed = 1;
  double size = 1.0;
  bool velocity = false;
  PlyEncoding plyEncoding = PlyEncoding::BinaryLittleEndian;
};

/// Writes one frame; returns the bytes of the file.
std::uintmax_t writeFrame(SynthFluid& source, const std::filesystem::path& path, const WriteOptions& options,
                          Progress& progress) {
  std::unique_ptr<ParticleWriter> writer = createParticleWriter(path, options);
  ParticleChunk current, next;
  bool more = source.read(current, kChunkParticles);
  while (more) {
    std::future<bool> ahead = std::async(std::launch::async, [&] { return source.read(next, kChunkParticles); });
    writer->write(current);
    progress.advance(current.size());
    more = ahead.get();
    std::swap(current, next);
  }
  writer->commit();
  return std::filesystem::file_size(path);
}

void runSynth(const SynthArguments& args) {
  SynthOptions options;
  options.particles = parseParticleCount(args.particles);
  options.seed = args.seed;
  options.size = args.size;
  options.velocity = args.velocity;
  FrameRange frames = parseFrameRange(args.frames);
  const bool sequence = frames.last > frames.first;
  if (sequence && !hasFramePattern(args.output))
    throw InputError("synth: -o '" + args.output + "' needs a frame pattern (####, %04d or {}) to write frames " +
                     args.frames);
  std::string extension = std::filesystem::path(args.output).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));

  SynthFluid first(options);  // validates the options and gives the per-frame count
  if (extension == ".vdb" && first.count() > kMaxVdbParticles)
    throw InputError("synth: VDB output holds a whole frame in memory (about 16 bytes a particle); " +
                     Progress::humanCount(double(first.count())) + " particles a frame is above the " +
                     Progress::humanCount(double(kMaxVdbParticles)) + " limit: write .ply or .bin instead");

  WriteOptions writeOptions;
  writeOptions.velocity = args.velocity;
  writeOptions.plyEncoding = args.plyEncoding;
  const std::uint64_t frameCount = std::uint64_t(frames.last - frames.first) + 1;
  Progress progress("synth", first.count() * frameCount);
  std::uintmax_t bytes = 0;
  for (int frame = frames.first; frame <= frames.last; ++frame) {
    progress.setLabel("synth frame " + std::to_string(frame - frames.first + 1) + "/" + std::to_string(frameCount));
    options.frame = frame;
    SynthFluid source(options);
    bytes += writeFrame(source, substituteFrame(args.output, frame), writeOptions, progress);
  }
  progress.finish();

  const Box domain = first.domain();
  std::string frameText = sequence ? "frames " + args.frames : "frame " + std::to_string(frames.first);
  std::printf(
      "synth: wrote %s to %s: %s particles a frame (%llu), %s in total, %sB\n", frameText.c_str(), args.output.c_str(),
      Progress::humanCount(double(first.count())).c_str(), static_cast<unsigned long long>(first.count()),
      Progress::humanCount(double(first.count() * frameCount)).c_str(), Progress::humanCount(double(bytes)).c_str());
  std::printf("synth: domain [0, 0, 0] - [%.6g, %.6g, %.6g] m, %.6g s a frame\n", domain.max.x, domain.max.y,
              domain.max.z, first.frameTime());
  std::printf("synth: 8 particles per cell in the body at: flipscope convert --cell-size %.9g\n", first.cellSize());
}

}  // namespace

void addSynthCommand(CLI::App& app) {
  auto args = std::make_shared<SynthArguments>();
  auto* cmd = app.add_subcommand(
      "synth",
      "Write procedural FLIP-like frames (wavy liquid body, crest sheets, spray) as .bin/.raw, .ply, .vdb, .bgeo, "
      ".bgeo.sc, .geo, .prt or .vtk");
  cmd->add_option("-o,--output", args->output,
                  "output file, its format by extension: .bin/.raw, .ply, .vdb, .bgeo, .bgeo.sc, .geo, .geo.sc, .prt, "
                  ".vtk; a frame pattern (####, %04d, {}) for several frames")
      ->required();
  cmd->add_option("--particles", args->particles, "particles a frame, 1k to 1G (suffixes k, M, G)")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "frame range A-B, or one frame A")->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the wave phases, jitter and spray")->capture_default_str();
  cmd->add_option("--size", args->size, "horizontal extent of the box in metres, about")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_flag("--velocity", args->velocity,
                "write velocities (PLY vx vy vz, VDB and Houdini v, PRT Velocity, VTK velocity; raw has none)");
  const std::map<std::string, PlyEncoding> encodings = {{"ascii", PlyEncoding::Ascii},
                                                        {"binary", PlyEncoding::BinaryLittleEndian},
                                                        {"binary_be", PlyEncoding::BinaryBigEndian}};
  cmd->add_option("--ply-encoding", args->plyEncoding, "PLY encoding: ascii, binary (little endian), binary_be")
      ->transform(CLI::CheckedTransformer(encodings, CLI::ignore_case));
  cmd->callback([args] { runSynth(*args); });
}

}  // namespace flipscope::tools
