// A farm job's plan (flipscope farm convert / render): which frames, in which chunks, with which
// options, run by which flipscope binary, into which store. Saved as JSON in the store's farm
// directory before anything is submitted, so that every task, the final summary and a later
// --resume read the same plan.
//
// Farm directory of a store (farmDirectory): STORE/farm/<convert|render>/
//   plan.json            this plan
//   jobs.json            every submission: role, scheduler job id, the frames of each task
//   scripts/<role>.sh    the job scripts (FarmScripts.h)
//   logs/                the scheduler's output of every task
//   bounds/task_N.json   the bounds pass: the particle bounds of task N's frames
//   failed/frame_N.log   why frame N failed, written by its task (removed when it succeeds)
//   summary.json, summary.txt   the final task's report (FarmSummary.h)
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tools/farm/Scheduler.h"

namespace flipscope::farm {

enum class FarmKind { Convert, Render };
const char* farmKindName(FarmKind kind);  ///< "convert", "render"

struct FarmPlan {
  FarmKind kind = FarmKind::Convert;
  std::filesystem::path store;      ///< absolute
  std::filesystem::path flipscope;  ///< the binary every task runs, absolute (on a shared path)
  std::vector<int> frames;          ///< every frame of the job, ascending
  int chunk = 1;                    ///< frames per array task
  FarmResources resources;

  // convert
  std::vector<std::string> inputs;       ///< as given, made absolute
  std::vector<std::string> grids;        ///< VDB point grids to read (--grid), for the bounds pass
  std::vector<std::string> prepareArgs;  ///< options of `convert --prepare` (domain, cell size, ...)
  std::vector<std::string> convertArgs;  ///< options of every task's `convert --append`
  bool boundsPass = false;               ///< no --domain: a bounds pass over the frames comes first

  // render
  std::string output;                    ///< absolute pattern with '#'
  std::filesystem::path camera;          ///< the one camera file every task renders with
  std::vector<std::string> renderArgs;   ///< options of every task's `render`
};

/// One submission of a farm job (jobs.json).
struct FarmSubmission {
  std::string role;                     ///< bounds, prepare, convert, render, finalize
  std::string job;                      ///< the scheduler's job id
  std::vector<std::vector<int>> tasks;  ///< the frames of each array task (empty: one task)
};

std::filesystem::path farmDirectory(const std::filesystem::path& store, FarmKind kind);

/// `frames` in chunks of `chunk` consecutive entries.
std::vector<std::vector<int>> chunkFrames(const std::vector<int>& frames, int chunk);

/// plan.json in the plan's farm directory (created), atomically.
void savePlan(const FarmPlan& plan);
/// Throws FileError naming plan.json when it is missing or damaged.
FarmPlan loadPlan(const std::filesystem::path& store, FarmKind kind);

/// jobs.json: every submission so far, oldest first (empty when there is none).
std::vector<FarmSubmission> loadSubmissions(const std::filesystem::path& farmDir);
void appendSubmissions(const std::filesystem::path& farmDir, const std::vector<FarmSubmission>& added);

}  // namespace flipscope::farm
