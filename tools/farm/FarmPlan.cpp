#include "tools/farm/FarmPlan.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "core/AtomicFile.h"
#include "core/Error.h"

namespace flipscope::farm {
namespace {

void writeJson(const std::filesystem::path& file, const nlohmann::json& json) {
  writeTextAtomically(file, json.dump(2) + "\n");
}

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw FileError(file, "missing (no farm job was planned here)");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {
    throw FileError(file, std::string("damaged: ") + e.what());
  }
}

}  // namespace

const char* farmKindName(FarmKind kind) { return kind == FarmKind::Convert ? "convert" : "render"; }

std::filesystem::path farmDirectory(const std::filesystem::path& store, FarmKind kind) {
  return store / "farm" / farmKindName(kind);
}

std::vector<std::vector<int>> chunkFrames(const std::vector<int>& frames, int chunk) {
  FLIPSCOPE_CHECK(chunk > 0, chunk);
  std::vector<std::vector<int>> chunks;
  for (std::size_t i = 0; i < frames.size(); i += std::size_t(chunk))
    chunks.emplace_back(frames.begin() + std::ptrdiff_t(i),
                        frames.begin() + std::ptrdiff_t(std::min(frames.size(), i + std::size_t(chunk))));
  return chunks;
}

void savePlan(const FarmPlan& p) {
  const nlohmann::json json = {
      {"kind", farmKindName(p.kind)},
      {"store", p.store.string()},
      {"flipscope", p.flipscope.string()},
      {"frames", p.frames},
      {"chunk", p.chunk},
      {"resources",
       {{"partition", p.resources.partition},
        {"time", p.resources.time},
        {"cpus", p.resources.cpus},
        {"memory", p.resources.memory}}},
      {"inputs", p.inputs},
      {"grids", p.grids},
      {"prepare_args", p.prepareArgs},
      {"convert_args", p.convertArgs},
      {"bounds_pass", p.boundsPass},
      {"output", p.output},
      {"camera", p.camera.string()},
      {"render_args", p.renderArgs},
  };
  const auto dir = farmDirectory(p.store, p.kind);
  std::filesystem::create_directories(dir);
  writeJson(dir / "plan.json", json);
}

FarmPlan loadPlan(const std::filesystem::path& store, FarmKind kind) {
  const auto file = farmDirectory(store, kind) / "plan.json";
  const nlohmann::json j = readJson(file);
  try {
    FarmPlan p;
    p.kind = j.at("kind").get<std::string>() == "render" ? FarmKind::Render : FarmKind::Convert;
    if (p.kind != kind) throw FileError(file, std::string("is not a plan of farm ") + farmKindName(kind));
    p.store = j.at("store").get<std::string>();
    p.flipscope = j.at("flipscope").get<std::string>();
    p.frames = j.at("frames").get<std::vector<int>>();
    p.chunk = j.at("chunk").get<int>();
    const auto& r = j.at("resources");
    p.resources = {r.at("partition"), r.at("time"), r.at("cpus"), r.at("memory")};
    p.inputs = j.at("inputs").get<std::vector<std::string>>();
    p.grids = j.at("grids").get<std::vector<std::string>>();
    p.prepareArgs = j.at("prepare_args").get<std::vector<std::string>>();
    p.convertArgs = j.at("convert_args").get<std::vector<std::string>>();
    p.boundsPass = j.at("bounds_pass").get<bool>();
    p.output = j.at("output").get<std::string>();
    p.camera = j.at("camera").get<std::string>();
    p.renderArgs = j.at("render_args").get<std::vector<std::string>>();
    if (p.chunk <= 0) throw FileError(file, "chunk must be positive");
    if (p.frames.empty()) throw FileError(file, "plans no frames");
    for (std::size_t i = 0; i < p.frames.size(); ++i)
      if (p.frames[i] < 0 || p.frames[i] > 999999 || (i > 0 && p.frames[i] <= p.frames[i - 1]))
        throw FileError(file, "frames must be ascending, unique, 0 to 999999 (frame " + std::to_string(p.frames[i]) +
                                  ")");
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw FileError(file, std::string("damaged: ") + e.what());
  }
}

std::vector<FarmSubmission> loadSubmissions(const std::filesystem::path& farmDir) {
  const auto file = farmDir / "jobs.json";
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return {};
  const nlohmann::json j = readJson(file);
  std::vector<FarmSubmission> list;
  try {
    for (const auto& s : j.at("submissions"))
      list.push_back({s.at("role"), s.at("job"), s.at("tasks").get<std::vector<std::vector<int>>>()});
  } catch (const nlohmann::json::exception& e) {
    throw FileError(file, std::string("damaged: ") + e.what());
  }
  return list;
}

void appendSubmissions(const std::filesystem::path& farmDir, const std::vector<FarmSubmission>& added) {
  std::vector<FarmSubmission> all = loadSubmissions(farmDir);
  all.insert(all.end(), added.begin(), added.end());
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : all) list.push_back({{"role", s.role}, {"job", s.job}, {"tasks", s.tasks}});
  writeJson(farmDir / "jobs.json", {{"submissions", list}});
}

}  // namespace flipscope::farm
