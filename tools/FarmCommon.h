// What the farm commands (FarmCommand.cpp, FarmTaskCommand.cpp) share: whether a planned frame
// is done, and the final summary as the final task wrote it.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tools/farm/FarmPlan.h"
#include "tools/farm/FarmSummary.h"

namespace CLI {
class App;
}

namespace flipscope::tools {

/// Checks planned frames: convert, listed in the store and verified (every checksum); render,
/// its image written. Opens the store once.
std::function<farm::FrameCheck(int)> farmFrameChecker(const farm::FarmPlan& plan);

/// The planned frames that are not done, ascending.
std::vector<int> framesNotDone(const farm::FarmPlan& plan);

/// summary.txt of the plan's farm directory; "" when the final task has not written it.
std::string readSummaryText(const farm::FarmPlan& plan);

/// summary.json's "complete"; nullopt when there is no (readable) summary.
std::optional<bool> summaryComplete(const farm::FarmPlan& plan);

/// `farm bounds` and `farm finalize`: the commands the farm's jobs run.
void addFarmTaskCommands(CLI::App& farm);

}  // namespace flipscope::tools
