// The jobs of a farm plan, as scripts a scheduler runs (Scheduler.h), in submission order:
//   convert: [bounds] array, one task per chunk: the particle bounds of its frames (only
//            without --domain; `flipscope farm bounds`)
//            prepare, after bounds: `flipscope convert --prepare` writes the store header once,
//            with the domain the bounds reduce to (`flipscope farm bounds --reduce`), the particle
//            spacing and attribute of the first frame that could be read
//            convert array, after prepare: `flipscope convert --append` of each frame of its chunk
//            finalize, after the array however it ended: `flipscope farm finalize`
//   render:  render array (`flipscope render` of each frame of its chunk, one camera file),
//            then finalize.
// A task converts or renders its frames one at a time, so a bad frame fails alone: its error goes
// to failed/frame_N.log in the farm directory (FarmPlan.h), and the task exits 1 at the end.
#pragma once

#include <string>
#include <vector>

#include "tools/farm/FarmPlan.h"
#include "tools/farm/Scheduler.h"

namespace flipscope::farm {

struct FarmJob {
  std::string role;                     ///< bounds, prepare, convert, render, finalize
  JobRequest request;                   ///< afterOk / afterAny hold roles until submitJobs()
  std::vector<std::vector<int>> tasks;  ///< the frames of each array task (empty: one task)
  std::string script;                   ///< the whole bash script
};

/// The jobs that do `frames` (all of the plan's, or those a resume needs) of `plan`;
/// `prepare`: write the store header first (a bounds pass too when the plan has one).
std::vector<FarmJob> planJobs(const FarmPlan& plan, const std::vector<int>& frames, bool prepare,
                              const Scheduler& scheduler);

/// Writes each job's script into the farm directory and submits them in order, dependencies
/// resolved to the job ids before them; records the submissions in jobs.json. A refused
/// submission throws InputError naming the jobs already queued.
std::vector<FarmSubmission> submitJobs(std::vector<FarmJob>& jobs, const FarmPlan& plan, Scheduler& scheduler);

/// What --dry-run prints: every script, each after the command that would submit it.
std::string describeJobs(const std::vector<FarmJob>& jobs, const Scheduler& scheduler);

}  // namespace flipscope::farm
