// The final task of a farm job (flipscope farm finalize): which planned frames are done, and
// for every other one why not: the error its task wrote (failed/frame_N.log), a frame that
// fails verification, or no result at all (a task cancelled or killed by the scheduler).
// Written to summary.json and summary.txt in the farm directory; `farm convert --resume`
// submits the frames that are not done.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "tools/farm/FarmPlan.h"

namespace flipscope::farm {

struct MissingFrame {
  int frame = 0;
  std::string reason;
};

struct FarmSummary {
  FarmKind kind = FarmKind::Convert;
  std::vector<int> planned;
  std::vector<int> done;
  std::vector<MissingFrame> missing;
  bool complete() const { return missing.empty(); }
};

/// What the command layer knows of one frame: done, or not (with the reason when it has one,
/// e.g. a verification failure; an empty reason is looked up in the task's failure log).
struct FrameCheck {
  bool done = false;
  std::string problem;
};

/// failed/frame_NNNNNN.log in `farmDir`: where a task writes why `frame` failed (FarmJobs.h).
std::filesystem::path failureLogPath(const std::filesystem::path& farmDir, int frame);

/// Checks every planned frame with `check`. `noResult`: the reason of a frame that is not done
/// and has no failure log.
FarmSummary summarize(const FarmPlan& plan, const std::function<FrameCheck(int)>& check, const std::string& noResult);

/// summary.txt's text: counts, then one line per frame that is not done.
std::string summaryText(const FarmSummary& summary, const FarmPlan& plan);

/// summary.json and summary.txt, atomically.
void writeSummary(const FarmSummary& summary, const FarmPlan& plan);

}  // namespace flipscope::farm
