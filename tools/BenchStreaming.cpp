// `flipscope bench streaming`: per-brick conversion and mipmap times for 32^3, 64^3 and 128^3
// bricks at low, paper-like and high fill on one core, bits per particle, and cache hit rates
// when scrubbing a synthetic sequence back and forth, beside the paper's Table 2 (Reichl et
// al. 2014 §5: Xeon X5560, one core per brick).
#include <time.h>

#include <cmath>
#include <cstdio>
#include <random>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "streaming/BrickMipmap.h"
#include "streaming/Streamer.h"
#include "streaming/SyntheticBrickSource.h"
#include "tools/JsonOutput.h"
#include "tools/Commands.h"

namespace flipscope::tools {
namespace {

// Paper-like fill: 64^3 bricks with a 4-cell border at Step's 5.85 bits per particle, one
// particle per cell, give 72^3 / 5.85 / 64^3 = 24 % occupied cells.
constexpr double kPaperFill = 0.25;
constexpr std::uint32_t kOverlap = 4;   // sphere radius 2 cells (Table 2) + jitter 1 + 1
constexpr std::uint32_t kDilation = 3;  // radius + jitter

struct PaperRow {
  std::uint32_t size;
  double conv, convSpread, mip;
};
constexpr PaperRow kPaperTable2[] = {{32, 0.06, 0.02, 0.01}, {64, 0.22, 0.06, 0.04}, {128, 0.91, 0.37, 0.27}};

struct Timing {
  double mean = 0, spread = 0;  // ms
};

// CPU time of the calling thread, in ms: one core's work, unaffected by other processes
// taking the core away (the build machines are shared).
double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

template <class F>
Timing timeMs(int reps, F&& f) {
  std::vector<double> ms;
  for (int r = 0; r < reps; ++r) {
    double t0 = threadCpuMs();
    f();
    ms.push_back(threadCpuMs() - t0);
  }
  Timing t;
  for (double m : ms) t.mean += m / double(reps);
  for (double m : ms) t.spread += (m - t.mean) * (m - t.mean) / double(reps);
  t.spread = std::sqrt(t.spread);
  return t;
}

DecodedBrick uniformBrick(std::uint32_t size, double fill, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  DecodedBrick brick;
  for (std::uint32_t c = 0; c < size * size * size; ++c) {
    if (unit(rng) >= fill) continue;
    std::uint32_t count = 1 + (rng() % 4 == 0);
    brick.cells.push_back(c);
    brick.counts.push_back(count);
    for (std::uint32_t p = 0; p < count; ++p) brick.attributes.push_back(std::uint16_t(rng()));
  }
  return brick;
}

struct ConversionRow {
  std::uint32_t size;
  double fill;
  Timing cells, assemble, conv, cold, mip;
  double bitsPerParticle;
};

ConversionRow benchConversion(std::uint32_t size, double fill, int reps) {
  ConversionRow row{size, fill};
  DecodedBrick brick = uniformBrick(size, fill, size * 1000 + std::uint32_t(fill * 100));
  ConversionOptions options{size, kOverlap, AttributeReduction::None};
  BrickCells cells = makeBrickCells(brick, size, options.attribute);
  Neighbourhood<BrickCells> around{};
  around.fill(&cells);  // every neighbour full with the same brick: the border is all copied
  Neighbourhood<DecodedBrick> decoded{};
  decoded.fill(&brick);
  BitBrick converted;
  std::vector<std::uint32_t> mip;
  row.cells = timeMs(reps, [&] { cells = makeBrickCells(brick, size, options.attribute); });
  row.assemble = timeMs(reps, [&] { converted = convertBrick(around, options); });
  row.conv = timeMs(
      reps, [&] { converted = convertBrick(around, options), cells = makeBrickCells(brick, size, options.attribute); });
  row.cold = timeMs(std::max(1, reps / 10), [&] { converted = convertBrick(decoded, options); });
  row.mip = timeMs(reps, [&] { mip = buildBrickMipmap(converted, kDilation); });
  row.bitsPerParticle = double(converted.bytes() * 8) / double(brick.particleCount());
  return row;
}

struct ScrubResult {
  std::string name;
  std::size_t budget;
  std::vector<double> hitRatePerPass;
  std::size_t cacheBytes;
};

ScrubResult scrub(const std::string& name, std::size_t budget, bool compress) {
  const int frames = 12;
  auto source = std::make_shared<SyntheticBrickSource>(32, glm::uvec3(8, 8, 4), frames, 0.3);
  StreamerOptions options;
  options.conversion = {32, kOverlap, AttributeReduction::Mean};
  options.mipDilation = kDilation;
  options.threads = 2;
  options.cacheBytes = budget;
  options.compressCache = compress;
  options.readAheadFrames = 2;
  Streamer streamer(source, options);
  streamer.setEye({-4, 4, 8});
  ScrubResult result{name, budget, {}, 0};
  for (int pass = 0; pass < 4; ++pass) {
    int direction = pass % 2 == 0 ? 1 : -1;
    StreamerStats before = streamer.stats();
    for (int i = 0; i < frames; ++i) {
      int frame = direction > 0 ? i : frames - 1 - i;
      streamer.setFrame(frame, direction);
      streamer.request(source->bricks(frame));
      streamer.waitIdle();
      streamer.takeReady(1u << 20);
    }
    StreamerStats after = streamer.stats();
    result.hitRatePerPass.push_back(double(after.deliveredFromCache - before.deliveredFromCache) /
                                    double(std::max<std::uint64_t>(1, after.delivered - before.delivered)));
  }
  result.cacheBytes = streamer.cache().bytes();
  return result;
}

void run(bool json, int reps) {
  std::vector<ConversionRow> rows;
  for (std::uint32_t size : {32u, 64u, 128u})
    for (double fill : {0.05, kPaperFill, 0.6})
      rows.push_back(benchConversion(size, fill, size == 128 ? std::max(1, reps / 4) : reps));

  // The synthetic sequence converts to about 60 MiB; half of it fits the smaller budget.
  std::vector<ScrubResult> scrubs = {scrub("all frames fit", std::size_t(1) << 30, false),
                                     scrub("budget 32 MiB", std::size_t(32) << 20, false),
                                     scrub("budget 32 MiB, zstd", std::size_t(32) << 20, true)};

  double msPerBrick64 = 0;
  for (const auto& r : rows)
    if (r.size == 64 && r.fill == kPaperFill) msPerBrick64 = r.conv.mean;

  if (json) {
    nlohmann::json out;
    out["ms_per_brick_64"] = msPerBrick64;
    out["ms_per_brick_64_fill"] = kPaperFill;
    out["ms_per_brick_64_note"] =
        "thread CPU time on one core; BrickCells of the brick (once per decoded brick) + assembly with a full 4-cell "
        "border; "
        "fill = fraction of occupied cells, paper-like from Table 1 Step (5.85 bits/particle)";
    for (const auto& r : rows)
      out["conversion"].push_back({{"brick_size", r.size},
                                   {"fill", r.fill},
                                   {"cells_ms", r.cells.mean},
                                   {"assemble_ms", r.assemble.mean},
                                   {"conv_ms", r.conv.mean},
                                   {"conv_ms_spread", r.conv.spread},
                                   {"cold_27_bricks_ms", r.cold.mean},
                                   {"mip_ms", r.mip.mean},
                                   {"bits_per_particle", r.bitsPerParticle}});
    for (const auto& p : kPaperTable2)
      out["paper_table2"].push_back(
          {{"brick_size", p.size}, {"conv_ms", p.conv}, {"conv_ms_spread", p.convSpread}, {"mip_ms", p.mip}});
    for (const auto& s : scrubs)
      out["cache"].push_back({{"name", s.name},
                              {"budget_bytes", s.budget},
                              {"hit_rate_per_pass", s.hitRatePerPass},
                              {"cache_bytes", s.cacheBytes}});
    printJson(out);
    return;
  }
  std::printf(
      "Brick conversion, thread CPU time on one core, overlap %u cells, mip dilation %u, no attributes (ms per brick, "
      "mean +- sd)\n",
      kOverlap, kDilation);
  std::printf("%5s %5s | %14s %9s %9s %9s %9s %6s | %11s %5s\n", "size", "fill", "conv", "cells", "assemble",
              "cold(27)", "mip", "bits/p", "paper conv", "mip");
  for (const auto& r : rows) {
    const PaperRow* p = nullptr;
    for (const auto& q : kPaperTable2)
      if (q.size == r.size) p = &q;
    std::printf("%5u %4.0f%% | %6.3f +- %5.3f %9.3f %9.3f %9.3f %9.3f %6.2f | %4.2f +- %4.2f %5.2f\n", r.size,
                r.fill * 100, r.conv.mean, r.conv.spread, r.cells.mean, r.assemble.mean, r.cold.mean, r.mip.mean,
                r.bitsPerParticle, p->conv, p->convSpread, p->mip);
  }
  std::printf("ms_per_brick_64 (fill %.0f%%, paper-like): %.3f ms (paper 0.22 +- 0.06, target 0.10)\n",
              kPaperFill * 100, msPerBrick64);
  std::printf(
      "\nCache hit rate, scrubbing 12 synthetic frames (32^3 bricks) forward, back, forward, back; read-ahead 2\n");
  for (const auto& s : scrubs) {
    std::printf("  %-20s", s.name.c_str());
    for (double h : s.hitRatePerPass) std::printf(" %5.1f%%", h * 100);
    std::printf("   (%.1f MiB held)\n", double(s.cacheBytes) / (1 << 20));
  }
}

}  // namespace

void addBenchStreamingCommand(CLI::App& bench) {
  auto* cmd =
      bench.add_subcommand("streaming", "Brick conversion, mipmap and cache timings beside the paper's Table 2");
  auto json = std::make_shared<bool>(false);
  auto reps = std::make_shared<int>(200);
  cmd->add_flag("--json", *json, "Print JSON (ms_per_brick_64 and every row)");
  cmd->add_option("--reps", *reps, "Repetitions per measurement (128^3: a quarter)")->check(CLI::Range(1, 100000));
  cmd->callback([json, reps] { run(*json, *reps); });
}

}  // namespace flipscope::tools
