#include "tools/farm/FarmSummary.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>

#include "core/AtomicFile.h"

namespace flipscope::farm {
namespace {

/// The reason a task wrote for `frame`: the first line flipscope reported as an error (it names
/// the file and what is wrong), else the log's last line; empty when there is no log.
std::string failureReason(const std::filesystem::path& farm, int frame) {
  std::ifstream in(failureLogPath(farm, frame));
  std::string line, error, last;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (error.empty() && line.find("error:") != std::string::npos) error = line;
    last = line;
  }
  return error.empty() ? last : error;
}

}  // namespace

std::filesystem::path failureLogPath(const std::filesystem::path& farmDir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.log", frame);
  return farmDir / "failed" / name;
}

FarmSummary summarize(const FarmPlan& plan, const std::function<FrameCheck(int)>& check,
                      const std::string& noResult) {
  const auto farm = farmDirectory(plan.store, plan.kind);
  FarmSummary s;
  s.kind = plan.kind;
  s.planned = plan.frames;
  for (int frame : plan.frames) {
    FrameCheck c = check(frame);
    if (c.done) {
      s.done.push_back(frame);
      continue;
    }
    if (c.problem.empty()) c.problem = failureReason(farm, frame);
    if (c.problem.empty()) c.problem = noResult;
    s.missing.push_back({frame, c.problem});
  }
  return s;
}

std::string summaryText(const FarmSummary& s, const FarmPlan& plan) {
  std::string text = "farm " + std::string(farmKindName(s.kind)) + " of " + plan.store.string() + ": " +
                     std::to_string(s.done.size()) + " of " + std::to_string(s.planned.size()) + " frames done";
  if (s.complete()) return text + ", complete\n";
  text += ", " + std::to_string(s.missing.size()) + " missing or failed:\n";
  for (const auto& m : s.missing) text += "  frame " + std::to_string(m.frame) + ": " + m.reason + "\n";
  text += "after fixing them: flipscope farm " + std::string(farmKindName(s.kind)) + " --resume " +
          (s.kind == FarmKind::Convert ? "-o " : "") + plan.store.string() + "\n";
  return text;
}

void writeSummary(const FarmSummary& s, const FarmPlan& plan) {
  const auto farm = farmDirectory(plan.store, plan.kind);
  nlohmann::json missing = nlohmann::json::array();
  for (const auto& m : s.missing) missing.push_back({{"frame", m.frame}, {"reason", m.reason}});
  const nlohmann::json json = {{"kind", farmKindName(s.kind)}, {"store", plan.store.string()},
                               {"planned", s.planned},         {"done", s.done},
                               {"missing", missing},           {"complete", s.complete()}};
  writeTextAtomically(farm / "summary.json", json.dump(2) + "\n");
  writeTextAtomically(farm / "summary.txt", summaryText(s, plan));
}

}  // namespace flipscope::farm
