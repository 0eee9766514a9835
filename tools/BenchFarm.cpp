// flipscope bench farm: farm convert on the Slurm cluster at hand (SLURM_CONF; e.g. the one
// tests/farm/run-slurm.sh starts) against a serial convert of the same synth sequence, in the
// same run; the scheduler's overhead per task, from an array of empty tasks; and, from the
// measured per-node rate and the uncached read rate of the frames, what a 300-frame, 500 M
// particle cache would take on farms of N nodes.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <vector>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/Progress.h"
#include "tools/BenchDisk.h"
#include "tools/CliChecks.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/farm/RunProgram.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

struct BenchFarmArgs {
  std::uint32_t frames = 8;
  std::string particles = "2M";
  int chunk = 1;
  int emptyTasks = 16;
  double sharedRead = 1.25;  ///< GB/s: a 10 Gb/s shared filesystem
  std::string workDir;
};

/// Runs flipscope with `args`; seconds of wall time. Throws InputError with its output on failure.
double timed(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {"/proc/self/exe"};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto start = std::chrono::steady_clock::now();
  const farm::ProgramRun run = farm::runProgram(argv);
  const double seconds = secondsSince(start);
  if (run.exitCode != 0) throw InputError("bench farm: flipscope " + args.front() + " failed:\n" + run.output);
  return seconds;
}

/// An array of `tasks` empty tasks through sbatch, waited for: seconds from submission to end.
double emptyArray(int tasks, const fs::path& dir) {
  const fs::path script = dir / "empty.sh";
  std::ofstream(script) << "#!/bin/bash\n#SBATCH --job-name=flipscope-bench-empty\n#SBATCH --output=" << (dir / "empty_%A_%a.log").string()
                        << "\ntrue\n";
  const auto start = std::chrono::steady_clock::now();
  const farm::ProgramRun submit =
      farm::runProgram({"sbatch", "--parsable", "--wait", "--array=0-" + std::to_string(tasks - 1), script.string()});
  if (submit.exitCode != 0) throw InputError("bench farm: sbatch of empty tasks failed: " + submit.output);
  return secondsSince(start);
}

void runBenchFarm(const BenchFarmArgs& a) {
  if (farm::runProgram({"sinfo", "-h", "-o", "%D %c"}).exitCode != 0)
    throw InputError(
        "bench farm: no Slurm cluster answers (sinfo failed); run it inside one, e.g. tests/farm/run-slurm.sh "
        "build/flipscope bench farm");
  const std::uint64_t particles = parseCount("--particles", a.particles);
  const fs::path work = a.workDir.empty() ? fs::temp_directory_path() / ("flipscope-bench-farm-" + std::to_string(::getpid()))
                                          : fs::path(a.workDir);
  fs::create_directories(work / "in");
  const std::string pattern = (work / "in" / "in_####.bin").string();
  const std::string frames = "1-" + std::to_string(a.frames);
  std::printf("bench farm: %u frames of %s particles (synth, raw float32), chunk %d\n", a.frames,
              a.particles.c_str(), a.chunk);
  timed({"synth", "-o", pattern, "--particles", a.particles, "--frames", frames});
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(work / "in")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  const double readRate = readUncached(files).bytesPerSecond();

  fs::remove_all(work / "serial");
  fs::remove_all(work / "farm");
  const double serial = timed({"convert", pattern, "-o", (work / "serial").string(), "-q"});
  const double farmWall =
      timed({"farm", "convert", pattern, "-o", (work / "farm").string(), "--chunk", std::to_string(a.chunk), "--wait"});
  const double empty = emptyArray(a.emptyTasks, work);
  const farm::ProgramRun nodes = farm::runProgram({"sinfo", "-h", "-o", "%D %c"});
  int nodeCount = 1, cpus = 1;
  std::sscanf(nodes.output.c_str(), "%d %d", &nodeCount, &cpus);

  const double total = double(particles) * a.frames;
  std::printf("\n%-44s %10s %14s\n", "", "wall s", "particles/s");
  std::printf("%-44s %10.2f %14s\n", "serial convert (one process)", serial,
              Progress::humanCount(total / serial).c_str());
  std::printf("%-44s %10.2f %14s\n",
              ("farm convert (" + std::to_string(nodeCount) + " node, " + std::to_string(cpus) + " CPUs)").c_str(),
              farmWall, Progress::humanCount(total / farmWall).c_str());
  std::printf("%-44s %10.2fx\n", "farm / serial", farmWall / serial);
  std::printf("%-44s %10.2f   (%d empty tasks: %.2f s wall, %d at a time)\n", "scheduling overhead per task, s",
              empty * std::min(cpus, a.emptyTasks) / a.emptyTasks, a.emptyTasks, empty, std::min(cpus, a.emptyTasks));
  std::printf("%-44s %10s\n", "uncached read of the frames",
              (Progress::humanCount(readRate) + "B/s").c_str());

  // On paper: 300 frames of 500 M particles (6 GB of raw float32 each, 1.8 TB in all). A node
  // converts at this run's serial rate; the farm as a whole reads at most the shared
  // filesystem's rate (--shared-read), each node at most this disk's uncached rate.
  const double cacheParticles = 300 * 500e6, cacheBytes = cacheParticles * 12;
  const double nodeRate = std::min(total / serial, readRate / 12);
  std::printf("\nOn paper: 300 frames x 500 M particles (%.1f TB raw), a node at %s particles/s (this run's serial "
              "convert, capped by its disk),\nthe farm's reads (each frame twice: bounds pass, convert) capped at %.2f GB/s (--shared-read)\n",
              cacheBytes / 1e12, Progress::humanCount(nodeRate).c_str(), a.sharedRead);
  std::printf("%-10s %14s %14s\n", "nodes", "minutes", "bound by");
  for (int n : {1, 4, 16, 64, 256}) {
    const double compute = cacheParticles / (nodeRate * n);
    const double network = 2 * cacheBytes / (a.sharedRead * 1e9);  // the bounds pass, then convert
    const double seconds = std::max(compute, network) + 300.0 / n * empty * std::min(cpus, a.emptyTasks) / a.emptyTasks;
    std::printf("%-10d %14.1f %14s\n", n, seconds / 60, compute >= network ? "conversion" : "network");
  }
  if (a.workDir.empty()) fs::remove_all(work);
}

}  // namespace

void addBenchFarmCommand(CLI::App& bench) {
  auto args = std::make_shared<BenchFarmArgs>();
  auto* cmd = bench.add_subcommand(
      "farm", "farm convert on the Slurm cluster at hand against a serial convert, the overhead per task, and a "
              "projection to big caches and farms");
  cmd->add_option("--frames", args->frames, "Frames of the synth sequence")->capture_default_str();
  cmd->add_option("--particles", args->particles, "Particles a frame")->capture_default_str();
  cmd->add_option("--chunk", args->chunk, "Frames per array task")->check(positiveCount())->capture_default_str();
  cmd->add_option("--empty-tasks", args->emptyTasks, "Empty tasks that measure the scheduler's overhead")
      ->check(positiveCount())
      ->capture_default_str();
  cmd->add_option("--shared-read", args->sharedRead, "Read rate of the farm's shared filesystem, GB/s")
      ->capture_default_str();
  cmd->add_option("--work-dir", args->workDir, "Where the frames and stores go (default: a temporary directory)");
  cmd->callback([args] { runBenchFarm(*args); });
}

}  // namespace flipscope::tools
