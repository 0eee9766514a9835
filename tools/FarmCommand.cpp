// flipscope farm convert | render | status: a whole cache converted, or a flipbook rendered, as
// array jobs on the farm's scheduler (tools/farm/: plan, job scripts, Slurm). The commands the
// jobs themselves run (farm bounds, farm finalize) are in FarmTaskCommand.cpp.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include "core/Error.h"
#include "core/NumberText.h"
#include "pipeline/RenderRequest.h"
#include "preprocess/Convert.h"
#include "preprocess/particles/InputSequence.h"
#include "preprocess/store/StoreInspection.h"
#include "raycast/Camera.h"
#include "streaming/BrickSource.h"
#include "tools/CliChecks.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/FarmCommon.h"
#include "tools/RenderJob.h"
#include "tools/farm/FarmJobs.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;
using farm::FarmKind;
using farm::FarmPlan;

/// What farm convert and farm render share: where the tasks run, how, and how to submit.
struct FarmArgs {
  int chunk = 0;  ///< 0: not given (1 for a new plan, the plan's on --resume)
  farm::FarmResources resources;
  std::string frames;
  std::string flipscope;
  bool dryRun = false;
  bool resume = false;
  bool wait = false;
};

void addFarmOptions(CLI::App* cmd, FarmArgs& a) {
  cmd->add_option("--frames", a.frames, "Frame range A-B (default: every frame)");
  cmd->add_option("--chunk", a.chunk, "Frames per array task (default 1; on --resume, the plan's)")
      ->check(positiveCount());
  cmd->add_option("--partition", a.resources.partition, "Scheduler partition (queue) of every task");
  cmd->add_option("--time", a.resources.time, "Wall-time limit of every task, e.g. 2:00:00");
  cmd->add_option("--cpus", a.resources.cpus, "CPUs of every task")->check(positiveCount());
  cmd->add_option("--mem", a.resources.memory, "Memory of every task, e.g. 16G");
  cmd->add_option("--flipscope", a.flipscope,
                  "The flipscope binary the tasks run, on a path every node sees (default: this one)");
  cmd->add_flag("--dry-run", a.dryRun, "Print the job scripts and the commands that would submit them; submit nothing");
  cmd->add_flag("--wait", a.wait, "Wait for the final task, print its summary, exit 1 when frames are missing");
}

/// The task memory as Slurm reads --mem: a number without a unit is MiB (K, M, G, T suffixes).
std::string slurmMemory(const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return text;
  return text + "M";
}

fs::path thisBinary() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("cannot find the flipscope binary (/proc/self/exe); give --flipscope");
  return self;
}

/// The options of `a` into the plan: all of them for a new plan; on --resume only those given,
/// over the plan's.
void fillCommon(FarmPlan& plan, const FarmArgs& a) {
  const bool fresh = !a.resume;
  if (a.chunk > 0 || fresh) plan.chunk = a.chunk > 0 ? a.chunk : 1;
  if (!a.resources.partition.empty() || fresh) plan.resources.partition = a.resources.partition;
  if (!a.resources.time.empty() || fresh) plan.resources.time = a.resources.time;
  if (a.resources.cpus > 0 || fresh) plan.resources.cpus = a.resources.cpus;
  if (!a.resources.memory.empty() || fresh) plan.resources.memory = slurmMemory(a.resources.memory);
  if (!a.flipscope.empty() || fresh) plan.flipscope = a.flipscope.empty() ? thisBinary() : fs::absolute(a.flipscope);
  if (!fs::exists(plan.flipscope)) throw FileError(plan.flipscope, "--flipscope: no such binary");
}

/// A resume while tasks of the earlier submissions still run would have two writers of a frame:
/// refused, naming them.
void refuseWhileRunning(const FarmPlan& plan) {
  auto scheduler = farm::makeSlurmScheduler();
  std::string running;
  for (const auto& s : farm::loadSubmissions(farm::farmDirectory(plan.store, plan.kind)))
    if (!scheduler->ended(s.job)) running += " " + s.job;
  if (!running.empty())
    throw InputError("farm " + std::string(farm::farmKindName(plan.kind)) + " --resume: jobs of " +
                     plan.store.string() + " are still queued or running:" + running +
                     "; wait for them (farm status) or cancel them first");
}

/// A --resume: the saved plan with the options given over it, and the frames that are not done
/// (none: it says so).
FarmPlan planToResume(const fs::path& store, FarmKind kind, const FarmArgs& a, std::vector<int>& todo) {
  FarmPlan plan = farm::loadPlan(store, kind);
  fillCommon(plan, a);
  if (!a.dryRun) refuseWhileRunning(plan);
  todo = framesNotDone(plan);
  if (todo.empty())
    std::printf("farm %s --resume: all %zu frames of %s are done\n", farm::farmKindName(kind), plan.frames.size(),
                store.c_str());
  return plan;
}

/// Before a submission: the summary and the failure logs of the frames about to run again go,
/// so that neither describes the last run.
void clearLastRun(const FarmPlan& plan, const std::vector<int>& frames) {
  const fs::path farmDir = farm::farmDirectory(plan.store, plan.kind);
  std::error_code ec;
  fs::remove(farmDir / "summary.txt", ec);
  fs::remove(farmDir / "summary.json", ec);
  for (int f : frames) fs::remove(farm::failureLogPath(farmDir, f), ec);
}

/// Submits (or, with --dry-run, prints) `jobs`, then reports how to follow them; with --wait,
/// waits for the final task and fails like it.
void launch(std::vector<farm::FarmJob>& jobs, const FarmPlan& plan, const FarmArgs& a) {
  auto scheduler = farm::makeSlurmScheduler();
  if (a.dryRun) {
    std::printf("%s", farm::describeJobs(jobs, *scheduler).c_str());
    std::printf("farm %s: dry run, nothing submitted (%zu jobs)\n", farm::farmKindName(plan.kind), jobs.size());
    return;
  }
  std::vector<int> frames;
  for (const auto& job : jobs)
    for (const auto& task : job.tasks) frames.insert(frames.end(), task.begin(), task.end());
  clearLastRun(plan, frames);
  std::vector<farm::FarmSubmission> submitted;
  try {
    submitted = farm::submitJobs(jobs, plan, *scheduler);
  } catch (const InputError&) {
    // Nothing was ever submitted for this plan: forget it, so that the same command can simply
    // be run again once the scheduler answers.
    const fs::path farmDir = farm::farmDirectory(plan.store, plan.kind);
    if (!a.resume && farm::loadSubmissions(farmDir).empty()) {
      std::error_code ec;
      fs::remove_all(farmDir, ec);
      for (const fs::path& dir : {farmDir.parent_path(), plan.store})
        if (fs::is_empty(dir, ec)) fs::remove(dir, ec);
    }
    throw;
  }
  std::string ids;
  for (const auto& s : submitted) {
    std::printf("submitted %s job %s%s\n", s.role.c_str(), s.job.c_str(),
                s.tasks.empty() ? "" : (" (" + std::to_string(s.tasks.size()) + " tasks)").c_str());
    ids += (ids.empty() ? "" : ",") + s.job;
  }
  const fs::path farmDir = farm::farmDirectory(plan.store, plan.kind);
  std::printf("follow: flipscope farm status %s   (or: squeue -j %s); logs in %s; the summary goes to %s\n",
              plan.store.c_str(), ids.c_str(), (farmDir / "logs").c_str(), (farmDir / "summary.txt").c_str());
  if (!a.wait) return;
  const std::string last = submitted.back().job;
  // Polled gently: every second at first, then every 5 s.
  for (int polls = 0; !scheduler->ended(last); ++polls)
    std::this_thread::sleep_for(std::chrono::milliseconds(polls < 30 ? 1000 : 5000));
  const std::string summary = readSummaryText(plan);
  std::printf("%s", summary.c_str());
  const std::optional<bool> complete = summaryComplete(plan);
  if (!complete) throw CommandFailed("farm: the final task wrote no summary; see " + (farmDir / "logs").string());
  if (!*complete) throw CommandFailed("farm: frames are missing");
}

std::optional<FrameRange> frameRange(const std::string& text) {
  if (text.empty()) return std::nullopt;
  return parseFrameRange(text);
}

// ---- farm convert

struct ConvertFarmArgs {
  FarmArgs farm;
  std::vector<std::string> inputs;
  std::string store;
  std::string domain;
  double cellSize = 0;
  std::uint32_t resolution = 0;
  std::optional<double> particleSpacing;
  std::uint32_t brickSize = 0;
  std::string attribute;
  std::string kindAttribute;
  std::vector<std::string> grids;
  int zstdLevel = 1;
  std::string scratch;
};

/// --mem of each task's convert: 85 % of the task's memory, the rest for the process itself.
/// `taskMemory` as Slurm reads it (slurmMemory).
std::string convertBudget(const std::string& taskMemory) {
  const std::uint64_t bytes = parseBytes("--mem", taskMemory);
  return std::to_string(std::max<std::uint64_t>(bytes / 100 * 85 >> 20, 16)) + "M";
}

void runFarmConvert(const ConvertFarmArgs& a) {
  if (a.store.empty()) throw InputError("farm convert: -o STORE is required");
  const fs::path store = fs::absolute(a.store);
  FarmPlan plan;
  std::vector<int> todo;
  bool prepare = true;
  if (a.farm.resume) {
    if (!a.inputs.empty()) throw InputError("farm convert --resume: the inputs come from the plan; give none");
    plan = planToResume(store, FarmKind::Convert, a.farm, todo);
    if (todo.empty()) return;
    prepare = !BrickStore::exists(store);  // the prepare job failed: write the header this time
  } else {
    if (a.inputs.empty()) throw InputError("farm convert: no inputs");
    if (fs::exists(farm::farmDirectory(store, FarmKind::Convert) / "plan.json") && !a.farm.dryRun)
      throw FileError(store, "has a farm convert planned already; continue it with farm convert --resume -o " +
                                 store.string());
    if (BrickStore::exists(store))
      throw FileError(store, "is a store already; farm convert makes a new one (append with convert --append)");
    plan.kind = FarmKind::Convert;
    plan.store = store;
    fillCommon(plan, a.farm);
    for (const auto& input : a.inputs) plan.inputs.push_back(fs::absolute(input).string());
    for (const auto& f : expandInputs(plan.inputs, frameRange(a.farm.frames))) plan.frames.push_back(f.frame);
    plan.grids = a.grids;
    plan.boundsPass = a.domain.empty();
    auto both = [&](const std::string& option, const std::string& value) {
      plan.prepareArgs.insert(plan.prepareArgs.end(), {option, value});
      plan.convertArgs.insert(plan.convertArgs.end(), {option, value});
    };
    if (!a.domain.empty()) both("--domain", formatBox(parseBox("--domain", a.domain)));  // also clips, as convert does
    for (const auto& grid : a.grids) both("--grid", grid);
    if (!a.kindAttribute.empty()) both("--kind-attribute", a.kindAttribute);
    if (!plan.resources.memory.empty()) both("--mem", convertBudget(plan.resources.memory));
    auto prepareOnly = [&](const std::string& option, const std::string& value) {
      plan.prepareArgs.insert(plan.prepareArgs.end(), {option, value});
    };
    if (a.cellSize > 0) prepareOnly("--cell-size", exactNumberText(a.cellSize));
    if (a.resolution > 0) prepareOnly("--resolution", std::to_string(a.resolution));
    if (a.particleSpacing) prepareOnly("--particle-spacing", exactNumberText(*a.particleSpacing));
    if (a.brickSize > 0) prepareOnly("--brick-size", std::to_string(a.brickSize));
    if (!a.attribute.empty()) prepareOnly("--attribute", a.attribute);
    plan.convertArgs.insert(plan.convertArgs.end(), {"--zstd-level", std::to_string(a.zstdLevel)});
    if (!a.scratch.empty()) plan.convertArgs.insert(plan.convertArgs.end(), {"--scratch", a.scratch});
    todo = plan.frames;
  }
  auto scheduler = farm::makeSlurmScheduler();
  auto jobs = farm::planJobs(plan, todo, prepare, *scheduler);
  if (!a.farm.dryRun) farm::savePlan(plan);
  std::printf("farm convert: %zu frames of %s into %s, %d per task%s\n", todo.size(),
              plan.inputs.empty() ? "?" : plan.inputs.front().c_str(), store.c_str(), plan.chunk,
              prepare ? (plan.boundsPass ? "; a bounds pass, then the store header" : "; the store header first")
                      : "");
  launch(jobs, plan, a.farm);
}

// ---- farm render

struct RenderFarmArgs {
  FarmArgs farm;
  std::string store;
  std::string output;
  std::string size = "1280x720";
  std::string up = "auto";
  std::string cameraFile;
};

void runFarmRender(const RenderFarmArgs& a, const std::vector<std::string>& extras) {
  const fs::path store = fs::absolute(a.store);
  FarmPlan plan;
  std::vector<int> todo;
  if (a.farm.resume) {
    plan = planToResume(store, FarmKind::Render, a.farm, todo);
    if (todo.empty()) return;
  } else {
    if (a.output.empty()) throw InputError("farm render: -o OUTPUT is required");
    if (a.output.find('#') == std::string::npos)
      throw InputError("farm render: the output name needs '#' for the frame number, e.g. out_####.exr");
    const BrickStore opened = BrickStore::open(store);
    if (opened.incomplete()) throw FileError(store, incompleteStoreReason());
    plan.kind = FarmKind::Render;
    plan.store = store;
    fillCommon(plan, a.farm);
    plan.output = fs::absolute(a.output).string();
    const auto range = frameRange(a.farm.frames);
    for (int f : opened.frames())
      if (!range || (f >= range->first && f <= range->last)) plan.frames.push_back(f);
    if (range)
      for (int f = range->first; f <= range->last; ++f)
        if (!opened.hasFrame(f)) throw InputError(store.string() + ": no frame " + std::to_string(f) + " in the store");
    if (plan.frames.empty()) throw InputError(store.string() + ": no frames to render");
    // One camera for the whole flipbook, as a local render of the range frames it.
    const fs::path farmDir = farm::farmDirectory(store, FarmKind::Render);
    plan.camera = farmDir / "camera.json";
    const auto [width, height] = parseImageSize("--size", a.size);
    Camera camera;
    if (!a.cameraFile.empty()) {
      camera = loadCamera(a.cameraFile);
    } else {
      StoreBrickSource source(opened);
      const UpAxis up = parseUpAxis("--up", a.up).value_or(opened.header().upAxis);
      std::uint64_t leftOut = 0;
      camera = defaultRenderCamera(source, plan.frames.front(), plan.frames.back(), width, height, upAxisVector(up),
                                   &leftOut);
      if (leftOut > 0)
        std::printf("farm render: %s\n", framingNote(leftOut, plan.frames.front() != plan.frames.back()).c_str());
    }
    if (!a.farm.dryRun) {
      fs::create_directories(farmDir);
      saveCamera(plan.camera, camera);
    }
    plan.renderArgs = {"--size", a.size};
    plan.renderArgs.insert(plan.renderArgs.end(), extras.begin(), extras.end());
    todo = plan.frames;
  }
  auto scheduler = farm::makeSlurmScheduler();
  auto jobs = farm::planJobs(plan, todo, false, *scheduler);
  if (!a.farm.dryRun) farm::savePlan(plan);
  std::printf("farm render: %zu frames of %s to %s, %d per task\n", todo.size(), store.c_str(), plan.output.c_str(),
              plan.chunk);
  launch(jobs, plan, a.farm);
}

// ---- farm status

void runFarmStatus(const std::vector<std::string>& targets) {
  std::vector<std::string> jobs;
  std::vector<fs::path> stores;
  for (const auto& t : targets) {
    if (fs::is_directory(t)) {
      stores.push_back(fs::absolute(t));
      for (FarmKind kind : {FarmKind::Convert, FarmKind::Render})
        for (const auto& s : farm::loadSubmissions(farm::farmDirectory(fs::absolute(t), kind))) jobs.push_back(s.job);
    } else if (!t.empty() && t.find_first_not_of("0123456789") == std::string::npos) {
      jobs.push_back(t);
    } else {
      throw InputError("farm status: '" + t + "' is neither a job id nor a store directory");
    }
  }
  if (jobs.empty()) throw InputError("farm status: no farm jobs were submitted for " + targets.front());
  auto scheduler = farm::makeSlurmScheduler();
  const auto tasks = scheduler->status(jobs);
  std::printf("%-10s %-6s %-20s %-12s %-6s %-10s %s\n", "job", "task", "name", "state", "exit", "elapsed", "reason");
  for (const auto& t : tasks)
    std::printf("%-10s %-6s %-20s %-12s %-6s %-10s %s\n", t.job.c_str(), t.task.empty() ? "-" : t.task.c_str(),
                t.name.c_str(), t.state.c_str(), t.exitCode.empty() ? "-" : t.exitCode.c_str(), t.elapsed.c_str(),
                t.reason.c_str());
  if (tasks.empty()) std::printf("(the scheduler no longer knows these jobs)\n");
  for (const auto& store : stores)
    for (FarmKind kind : {FarmKind::Convert, FarmKind::Render}) {
      std::error_code ec;
      if (!fs::exists(farm::farmDirectory(store, kind) / "plan.json", ec)) continue;
      const std::string summary = readSummaryText(farm::loadPlan(store, kind));
      std::printf("%s", summary.empty() ? ("farm " + std::string(farm::farmKindName(kind)) + ": no summary yet\n").c_str()
                                        : summary.c_str());
    }
}

}  // namespace

void addFarmCommand(CLI::App& app) {
  auto* farmCmd = app.add_subcommand("farm", "Convert a cache or render a flipbook as array jobs on a Slurm farm");
  farmCmd->require_subcommand(1);

  auto convert = std::make_shared<ConvertFarmArgs>();
  auto* c = farmCmd->add_subcommand(
      "convert", "Convert frames as an array job (one task per chunk) into one store, then verify and summarise");
  c->add_option("inputs", convert->inputs, "Input files or patterns, as for convert (none with --resume)");
  c->add_option("-o,--output", convert->store, "The brick store to create (on a filesystem every node sees)")
      ->required();
  addFarmOptions(c, convert->farm);
  c->add_flag("--resume", convert->farm.resume, "Submit only the frames the store lacks (after a failed task)");
  c->add_option("--domain", convert->domain, "x0,y0,z0,x1,y1,z1 (default: a bounds pass over the frames, in parallel)");
  auto* cell = c->add_option("--cell-size", convert->cellSize, "Cell size in world units (default: as convert)")
                   ->check(positiveNumber());
  c->add_option("--resolution", convert->resolution, "Cells along the longest domain axis")
      ->check(positiveCount())
      ->excludes(cell);
  c->add_option("--particle-spacing", convert->particleSpacing,
                "Particle spacing in world units (default: measured, as convert; 0: unknown)")
      ->check(nonNegativeNumber());
  c->add_option("--brick-size", convert->brickSize, "Cells per brick edge")->check(CLI::IsMember({32, 64, 128}));
  c->add_option("--attribute", convert->attribute, "Per-particle attribute to store, as for convert");
  c->add_option("--kind-attribute", convert->kindAttribute, "Particle type attribute (auto, none or a name), as for convert");
  c->add_option("--grid", convert->grids, "VDB: PointDataGrid names to read");
  c->add_option("--zstd-level", convert->zstdLevel, "zstd level of brick payloads")->check(CLI::Range(-5, 19));
  c->add_option("--scratch", convert->scratch,
                "Spill directory of each task's out-of-core convert, on the node's own disk, e.g. /tmp (default: "
                "the store)");
  c->callback([convert] { runFarmConvert(*convert); });

  auto render = std::make_shared<RenderFarmArgs>();
  auto* r = farmCmd->add_subcommand("render",
                                    "Render a flipbook as an array job, every frame with one camera, as render would");
  r->add_option("store", render->store, "Brick store directory")->required();
  r->add_option("-o,--output", render->output, "Output .exr or .png with '#' for the frame number");
  addFarmOptions(r, render->farm);
  r->add_flag("--resume", render->farm.resume, "Submit only the frames whose image is missing");
  r->add_option("--size", render->size, "Image size WxH")->capture_default_str();
  r->add_option("--up", render->up, "Up axis of the default camera: auto (the one the store records, else y), x, y or z")->capture_default_str();
  r->add_option("--camera-file", render->cameraFile, "Camera JSON (default: framed on every frame, as render does)");
  r->allow_extras();  // every other option goes to each task's render (e.g. --smoothing, --shading)
  r->footer("Other options are passed to every task's flipscope render.");
  r->callback([render, r] { runFarmRender(*render, r->remaining()); });

  auto targets = std::make_shared<std::vector<std::string>>();
  auto* s = farmCmd->add_subcommand("status", "Each task's state (squeue, sacct) and the summary, by job id or store");
  s->add_option("targets", *targets, "Job ids or store directories")->required();
  s->callback([targets] { runFarmStatus(*targets); });

  addFarmTaskCommands(*farmCmd);
}

}  // namespace flipscope::tools
