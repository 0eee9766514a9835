#include "tools/BenchFormats.h"

#include <chrono>
#include <cstdio>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/Progress.h"
#include "preprocess/SynthFluid.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"
#include "tools/ChildProcess.h"
#include "tools/CliValues.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

/// The fixed overhead beyond --mem that convert documents (README, Reliability).
constexpr double kFixedOverheadMiB = 48;

/// Writes the synth frame as `path` unless it exists (not timed).
void writeSynth(const fs::path& path, std::uint64_t particles) {
  if (fs::exists(path)) return;
  SynthOptions synth;
  synth.particles = particles;
  synth.velocity = path.extension() != ".bin";
  SynthFluid fluid(synth);
  std::fprintf(stderr, "bench preprocess: writing %s particles into %s ...\n",
               Progress::humanCount(double(fluid.count())).c_str(), path.c_str());
  WriteOptions options;
  options.velocity = synth.velocity;
  auto writer = createParticleWriter(path, options);
  ParticleChunk chunk;
  while (fluid.read(chunk, 1 << 20)) writer->write(chunk);
  writer->commit();
}

struct ReadTiming {
  std::uint64_t particles = 0;
  double seconds = 0;
  bool velocity = false;
};

/// Reads every particle (positions and velocities) through the registry; best of two passes,
/// the first warms the page cache.
ReadTiming timeRead(const fs::path& path) {
  ReadTiming best;
  for (int pass = 0; pass < 2; ++pass) {
    const auto start = std::chrono::steady_clock::now();
    auto source = openParticleFile(path);
    ParticleChunk chunk;
    std::uint64_t n = 0;
    while (source->read(chunk, 1 << 20)) n += chunk.size();
    const double seconds = secondsSince(start);
    if (pass == 0 || seconds < best.seconds) best = {n, seconds, source->hasVelocity()};
  }
  return best;
}

}  // namespace

nlohmann::json benchFormats(const FormatBenchOptions& options) {
  const fs::path raw = options.workDir / "formats.bin";
  writeSynth(raw, options.particles);
  nlohmann::json rows = nlohmann::json::array();
  const ReadTiming rawRead = timeRead(raw);
  const double rawRate = double(rawRead.particles) / rawRead.seconds;
  for (const std::string& format : options.formats) {
    const fs::path file = options.workDir / ("formats." + format);
    writeSynth(file, options.particles);
    const ReadTiming read = timeRead(file);
    const fs::path store = options.workDir / ("store-" + format);
    fs::remove_all(store);
    const ChildRun convert = runFlipscopeChild({"convert", file.string(), "-o", store.string(), "--mem", options.mem},
                                               options.workDir / ("convert-" + format + ".log"));
    fs::remove_all(store);
    const double rate = double(read.particles) / read.seconds;
    rows.push_back({{"format", format},
                    {"file_bytes", fs::file_size(file)},
                    {"particles", read.particles},
                    {"velocity", read.velocity},
                    {"read_s", read.seconds},
                    {"read_particles_per_s", rate},
                    {"ratio_to_raw_float_read", rate / rawRate},
                    {"convert_exit_code", convert.exitCode},
                    {"convert_s", convert.seconds},
                    {"convert_peak_rss_mib", convert.reportedPeakMiB}});
  }
  return {{"raw_float_read_particles_per_s", rawRate},
          {"raw_float_read_s", rawRead.seconds},
          {"particles", rawRead.particles},
          {"mem", options.mem},
          {"fixed_overhead_mib", kFixedOverheadMiB},
          {"formats", rows}};
}

void printFormatTable(const nlohmann::json& result, const FormatBenchOptions& options) {
  std::printf("\nreaders: the same %s synth particles (positions, and velocities where the format has them) in each "
              "format, read through flipscope's reader (page cache warm, best of 2); convert --mem %s of each in a "
              "child process\n\n",
              Progress::humanCount(result["particles"].get<double>()).c_str(), options.mem.c_str());
  std::printf("%-10s %10s %10s %14s %12s %11s %15s\n", "format", "file", "read s", "particles/s", "x raw float",
              "convert s", "peak RSS MiB");
  std::printf("%-10s %10s %10.3f %14s %12s %11s %15s\n", "raw float", "", result["raw_float_read_s"].get<double>(),
              Progress::humanCount(result["raw_float_read_particles_per_s"].get<double>()).c_str(), "1.00", "", "");
  const double budgetMiB = double(parseBytes("--mem", options.mem)) / (1 << 20);
  for (const auto& row : result["formats"]) {
    const double peak = row["convert_peak_rss_mib"].get<double>();
    std::printf("%-10s %10s %10.3f %14s %12.2f %11.2f %9.0f %s\n", row["format"].get<std::string>().c_str(),
                (Progress::humanCount(row["file_bytes"].get<double>()) + "B").c_str(), row["read_s"].get<double>(),
                Progress::humanCount(row["read_particles_per_s"].get<double>()).c_str(),
                row["ratio_to_raw_float_read"].get<double>(), row["convert_s"].get<double>(), peak,
                row["convert_exit_code"].get<int>() != 0 ? "(convert failed)"
                : peak <= budgetMiB + kFixedOverheadMiB ? "ok"
                                                        : "OVER");
  }
  std::printf("\ntargets: uncompressed readers >= 0.5x the raw-float read; convert peak RSS <= --mem + %.0f MiB\n",
              kFixedOverheadMiB);
}

}  // namespace flipscope::tools
