// The commands a farm job's tasks run (tools/farm/FarmJobs.h), beside the ordinary convert and
// render: `farm bounds` (the bounds pass and its reduction to one domain) and `farm finalize`
// (the final task: every planned frame checked, summary.json and summary.txt written).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <algorithm>
#include <memory>
#include <optional>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/Convert.h"
#include "preprocess/particles/InputSequence.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/FarmCommon.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

fs::path boundsFile(const farm::FarmPlan& plan, int task) {
  return farm::farmDirectory(plan.store, plan.kind) / "bounds" / ("task_" + std::to_string(task) + ".json");
}

/// One bounds task: the particle bounds of its frames, to bounds/task_N.json.
void writeTaskBounds(const farm::FarmPlan& plan, int task, const std::vector<int>& frames) {
  ConvertOptions options;
  options.read.grids = plan.grids;
  options.progress = Progress::Mode::Silent;
  Box bounds;
  std::vector<int> failed;
  for (int f : frames) {
    // A frame that cannot be read fails here and again in its convert task, which names it in
    // the summary; the other frames still make the domain.
    try {
      const auto inputs = expandInputs(plan.inputs, FrameRange{f, f});
      const Box frameBounds = scanInputBounds(inputs, options);
      bounds.extend(frameBounds);
      std::printf("frame %d: bounds %s\n", f, frameBounds.isEmpty() ? "empty" : formatBox(frameBounds).c_str());
    } catch (const InputError& e) {
      std::fprintf(stderr, "flipscope: error: frame %d: %s\n", f, e.what());
      failed.push_back(f);
    }
  }
  nlohmann::json json = {{"task", task}, {"frames", frames}, {"failed", failed}, {"empty", bounds.isEmpty()}};
  if (!bounds.isEmpty()) {
    json["min"] = {bounds.min.x, bounds.min.y, bounds.min.z};
    json["max"] = {bounds.max.x, bounds.max.y, bounds.max.z};
  }
  const fs::path file = boundsFile(plan, task);
  fs::create_directories(file.parent_path());
  writeTextAtomically(file, json.dump(2) + "\n");
}

/// The union of every task's bounds: the domain of the store, as convert would find it; and the
/// first frame that could be read.
std::pair<Box, int> reduceBounds(const farm::FarmPlan& plan) {
  Box domain;
  std::optional<int> first;
  const auto chunks = farm::chunkFrames(plan.frames, plan.chunk);
  for (std::size_t task = 0; task < chunks.size(); ++task) {
    const fs::path file = boundsFile(plan, int(task));
    std::ifstream in(file);
    if (!in) throw FileError(file, "missing: bounds task " + std::to_string(task) + " did not finish");
    try {
      const nlohmann::json j = nlohmann::json::parse(in);
      if (j.at("frames").get<std::vector<int>>() != chunks[task])
        throw FileError(file, "holds the bounds of other frames than task " + std::to_string(task) + "'s");
      const auto failed = j.at("failed").get<std::vector<int>>();
      for (int f : failed)
        std::fprintf(stderr, "warning: frame %d could not be read in the bounds pass; the domain is that of the others\n",
                     f);
      for (int f : chunks[task])
        if (!first && std::find(failed.begin(), failed.end(), f) == failed.end()) first = f;
      if (j.at("empty").get<bool>()) continue;
      const auto lo = j.at("min").get<std::vector<double>>(), hi = j.at("max").get<std::vector<double>>();
      if (lo.size() != 3 || hi.size() != 3) throw FileError(file, "min and max need three numbers each");
      domain.extend(Box{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}});
    } catch (const nlohmann::json::exception& e) {
      throw FileError(file, std::string("damaged: ") + e.what());
    }
  }
  if (domain.isEmpty())
    throw InputError(plan.store.string() +
                     ": no finite particle positions in any frame: cannot derive a domain (give --domain)");
  if (!first)
    throw FileError(boundsFile(plan, 0).parent_path(), "the bounds files list every frame as failed, yet not empty");
  return {domain, *first};
}

struct BoundsArgs {
  std::string store;
  int task = -1;
  std::vector<int> frames;
  bool reduce = false;
};

void runBounds(const BoundsArgs& a) {
  const farm::FarmPlan plan = farm::loadPlan(fs::absolute(a.store), farm::FarmKind::Convert);
  if (a.reduce) {
    const auto [domain, first] = reduceBounds(plan);
    std::printf("%s %d\n", formatBox(domain).c_str(), first);
    return;
  }
  if (a.task < 0 || a.frames.empty()) throw InputError("farm bounds: give --task N and its frames, or --reduce");
  writeTaskBounds(plan, a.task, a.frames);
}

void runFinalize(const std::string& store, const std::string& kind) {
  const farm::FarmKind k = kind == "render" ? farm::FarmKind::Render : farm::FarmKind::Convert;
  const farm::FarmPlan plan = farm::loadPlan(fs::absolute(store), k);
  const std::string noResult = "no result: its task did not finish (cancelled, killed, or never ran); see " +
                               (farm::farmDirectory(plan.store, k) / "logs").string();
  const farm::FarmSummary summary = farm::summarize(plan, farmFrameChecker(plan), noResult);
  farm::writeSummary(summary, plan);
  std::printf("%s", farm::summaryText(summary, plan).c_str());
  if (!summary.complete())
    throw CommandFailed("farm finalize: " + std::to_string(summary.missing.size()) + " frames missing or failed");
}

}  // namespace

void addFarmTaskCommands(CLI::App& farmCmd) {
  auto bounds = std::make_shared<BoundsArgs>();
  auto* b = farmCmd.add_subcommand("bounds", "(run by farm convert's jobs) particle bounds of a task's frames");
  b->add_option("store", bounds->store, "The store being converted")->required();
  b->add_option("--task", bounds->task, "Array task index");
  b->add_option("frames", bounds->frames, "The task's frames");
  b->add_flag("--reduce", bounds->reduce,
              "Print the union of every task's bounds as --domain reads it, and the first frame read");
  b->callback([bounds] { runBounds(*bounds); });

  auto store = std::make_shared<std::string>();
  auto kind = std::make_shared<std::string>("convert");
  auto* f = farmCmd.add_subcommand("finalize", "(run by the final job) check every planned frame, write the summary");
  f->add_option("store", *store, "The store")->required();
  f->add_option("--kind", *kind, "convert or render")->check(CLI::IsMember({"convert", "render"}))->capture_default_str();
  f->callback([store, kind] { runFinalize(*store, *kind); });
}

}  // namespace flipscope::tools
