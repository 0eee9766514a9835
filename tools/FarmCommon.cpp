#include "tools/FarmCommon.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <memory>
#include <sstream>

#include "core/Error.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/store/StoreInspection.h"
#include "tools/RenderJob.h"

namespace flipscope::tools {

std::function<farm::FrameCheck(int)> farmFrameChecker(const farm::FarmPlan& plan) {
  if (plan.kind == farm::FarmKind::Render) {
    return [output = plan.output](int frame) {
      std::error_code ec;
      const auto file = outputPathForFrame(output, frame);
      return farm::FrameCheck{std::filesystem::file_size(file, ec) > 0 && !ec, ""};
    };
  }
  std::shared_ptr<BrickStore> store;
  std::string unusable;
  try {
    store = std::make_shared<BrickStore>(BrickStore::open(plan.store));
  } catch (const InputError& e) {
    unusable = std::string(e.what()) + " (the prepare job did not write the store header: see its log in " +
               (farm::farmDirectory(plan.store, plan.kind) / "logs").string() + ")";
  }
  return [store, unusable](int frame) -> farm::FrameCheck {
    if (!store) return {false, unusable};
    if (!store->hasFrame(frame)) return {false, ""};
    try {
      const auto problems = verifyFrame(*store, *store->frame(frame));
      if (!problems.empty()) return {false, problems.front()};
    } catch (const InputError& e) {
      return {false, e.what()};
    }
    return {true, ""};
  };
}

std::vector<int> framesNotDone(const farm::FarmPlan& plan) {
  const auto check = farmFrameChecker(plan);
  std::vector<int> frames;
  for (int f : plan.frames)
    if (!check(f).done) frames.push_back(f);
  return frames;
}

std::string readSummaryText(const farm::FarmPlan& plan) {
  std::ifstream in(farm::farmDirectory(plan.store, plan.kind) / "summary.txt");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<bool> summaryComplete(const farm::FarmPlan& plan) {
  std::ifstream in(farm::farmDirectory(plan.store, plan.kind) / "summary.json");
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in).at("complete").get<bool>();
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

}  // namespace flipscope::tools
