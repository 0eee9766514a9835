// flipscope inspect: what particle inputs hold, before converting them (issue 11). For each
// input: the format and its version, the compressed containers around it, the point count,
// the bounds, every attribute with its type, arity and range, and for a frame pattern the
// frames it finds (the first frame's file is inspected). It reads the headers, then positions
// and attributes in chunks for bounds and ranges (nothing is converted); --header-only stops
// after the headers, so a file of any size answers at once.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "core/Box.h"
#include "core/Elapsed.h"
#include "core/Error.h"
#include "preprocess/particles/InputSequence.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "tools/Commands.h"
#include "tools/JsonOutput.h"

namespace flipscope::tools {
namespace {

struct InspectArgs {
  std::vector<std::string> inputs;
  bool json = false;
  bool headerOnly = false;
};

struct Range {
  std::vector<double> min, max;  ///< per component, over finite values
  std::uint64_t nonFinite = 0;
};

/// What one file holds (the JSON of one input).
nlohmann::json inspectFile(const std::filesystem::path& path, bool headerOnly) {
  const auto start = std::chrono::steady_clock::now();
  RecognisedInput input = recogniseInput(InputFile(path));
  const ParticleFormat& format = *input.format;
  std::unique_ptr<ParticleSource> source = format.open(std::move(input.file), ReadOptions{});
  const std::vector<AttributeDesc> attributes = source->attributes();
  // Every attribute the reader decodes: a file may list some it cannot (OpenVDB group and
  // string arrays), which are then shown without a range.
  std::vector<std::string> undecodable;
  if (!headerOnly && !attributes.empty()) {
    ReadOptions every;
    every.allAttributes = true;
    try {
      source = openParticleFile(path, every);
    } catch (const FileError&) {
      ReadOptions decodable;
      for (const AttributeDesc& attribute : attributes) {
        ReadOptions one;
        one.attributes = {attribute.name};
        try {
          auto probe = openParticleFile(path, one);
          ParticleChunk chunk;
          probe->read(chunk, 1);
          decodable.attributes.push_back(attribute.name);
        } catch (const FileError& e) {
          undecodable.push_back(attribute.name);
          std::fprintf(stderr, "inspect: %s\n", e.what());
        }
      }
      source = openParticleFile(path, decodable);
    }
  }

  nlohmann::json j;
  j["file"] = path.string();
  j["format"] = format.name;
  j["format_description"] = source->format();
  j["containers"] = input.containers;
  const auto declared = source->countHint();
  j["points_declared"] = declared ? nlohmann::json(*declared) : nlohmann::json(nullptr);
  j["velocity"] = source->hasVelocity();
  const auto kind = source->kindAttribute();
  j["kind_attribute"] = kind ? nlohmann::json(*kind) : nlohmann::json(nullptr);
  const UpAxis up = source->upAxis();  // null: the file's conventions do not say
  j["up_axis"] = up == UpAxis::Unknown ? nlohmann::json(nullptr) : nlohmann::json(upAxisName(up));

  std::vector<Range> ranges(attributes.size());
  for (std::size_t a = 0; a < attributes.size(); ++a) {
    ranges[a].min.assign(std::size_t(attributes[a].arity), std::numeric_limits<double>::infinity());
    ranges[a].max.assign(std::size_t(attributes[a].arity), -std::numeric_limits<double>::infinity());
  }
  if (!headerOnly) {
    Box bounds;
    std::uint64_t points = 0, nonFinitePositions = 0;
    ParticleChunk chunk;
    while (source->read(chunk, 1 << 16)) {
      points += chunk.size();
      for (const glm::vec3& p : chunk.positions) {
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
          bounds.extend(glm::dvec3(p));
        else
          ++nonFinitePositions;
      }
      for (const AttributeColumn& column : chunk.attributes) {
        std::size_t a = 0;
        while (a < attributes.size() && attributes[a].name != column.name) ++a;
        if (a == attributes.size() || attributes[a].arity != column.arity) continue;
        Range& range = ranges[a];
        for (std::size_t i = 0; i < column.values.size(); ++i) {
          const double v = column.values[i];
          const std::size_t c = i % std::size_t(column.arity);
          if (!std::isfinite(v)) {
            ++range.nonFinite;
            continue;
          }
          range.min[c] = std::min(range.min[c], v);
          range.max[c] = std::max(range.max[c], v);
        }
      }
    }
    j["points"] = points;
    j["non_finite_positions"] = nonFinitePositions;
    if (!bounds.isEmpty())
      j["bounds"] = {{"min", {bounds.min.x, bounds.min.y, bounds.min.z}}, {"max", {bounds.max.x, bounds.max.y, bounds.max.z}}};
    else
      j["bounds"] = nullptr;
  }
  j["attributes"] = nlohmann::json::array();
  for (std::size_t a = 0; a < attributes.size(); ++a) {
    nlohmann::json attribute{{"name", attributes[a].name},
                             {"type", std::string(valueTypeName(attributes[a].type))},
                             {"arity", attributes[a].arity}};
    const bool decoded = std::find(undecodable.begin(), undecodable.end(), attributes[a].name) == undecodable.end();
    attribute["decoded"] = !headerOnly && decoded;
    if (!headerOnly && decoded) {
      const bool any = !ranges[a].min.empty() && std::isfinite(ranges[a].min[0]);
      attribute["min"] = any ? nlohmann::json(ranges[a].min) : nlohmann::json(nullptr);
      attribute["max"] = any ? nlohmann::json(ranges[a].max) : nlohmann::json(nullptr);
      attribute["non_finite"] = ranges[a].nonFinite;
    }
    j["attributes"].push_back(std::move(attribute));
  }
  j["undecodable_attributes"] = undecodable;
  j["seconds"] = secondsSince(start);
  return j;
}

std::string numbers(const nlohmann::json& values) {
  std::string text;
  for (const auto& v : values) {
    text += (text.empty() ? "" : ", ") + numberText(v.get<double>());
  }
  return values.size() == 1 ? text : "(" + text + ")";
}

void printFile(const nlohmann::json& j) {
  std::printf("%s\n", j["file"].get<std::string>().c_str());
  std::string containers;
  for (const auto& c : j["containers"]) containers += " in a " + c.get<std::string>() + " container";
  std::printf("  format      %s%s\n", j["format_description"].get<std::string>().c_str(), containers.c_str());
  const std::string declared =
      j["points_declared"].is_null() ? "not in the header" : std::to_string(j["points_declared"].get<std::uint64_t>());
  if (j.contains("points"))
    std::printf("  points      %llu (header: %s)\n", (unsigned long long)j["points"].get<std::uint64_t>(),
                declared.c_str());
  else
    std::printf("  points      %s (header)\n", declared.c_str());
  if (j.contains("bounds") && !j["bounds"].is_null())
    std::printf("  bounds      %s - %s\n", numbers(j["bounds"]["min"]).c_str(), numbers(j["bounds"]["max"]).c_str());
  if (j.value("non_finite_positions", 0) > 0)
    std::printf("  non-finite  %llu positions (NaN/Inf: convert skips them)\n",
                (unsigned long long)j["non_finite_positions"].get<std::uint64_t>());
  if (j["attributes"].empty()) {
    std::printf("  attributes  none (positions only)\n");
  } else {
    std::printf("  attributes  %-16s %-8s %5s  %s\n", "name", "type", "arity", j.contains("points") ? "range" : "");
    for (const auto& a : j["attributes"]) {
      std::string range;
      if (j.contains("points") && !a["decoded"].get<bool>())
        range = "not decoded (flipscope does not read this kind of attribute)";
      else if (a.contains("min"))
        range = !a["min"].is_null()         ? numbers(a["min"]) + " to " + numbers(a["max"])
                : j.value("points", 0) == 0 ? "no values (no points)"
                                            : "no finite values";
      std::printf("              %-16s %-8s %5d  %s\n", a["name"].get<std::string>().c_str(),
                  a["type"].get<std::string>().c_str(), a["arity"].get<int>(), range.c_str());
    }
  }
  std::printf("  velocity    %s\n", j["velocity"].get<bool>() ? "yes (convert stores speed by default)" : "no");
  if (!j["kind_attribute"].is_null())
    std::printf("  kinds       %s: particle types (Mantaflow's flags), convert stores a kind per cell\n",
                j["kind_attribute"].get<std::string>().c_str());
  if (!j["up_axis"].is_null())
    std::printf("  up axis     %s (the file's conventions; convert records it)\n",
                j["up_axis"].get<std::string>().c_str());
}

void runInspect(const InspectArgs& a) {
  nlohmann::json all = nlohmann::json::array();
  for (const std::string& input : a.inputs) {
    nlohmann::json entry;
    std::filesystem::path file = input;
    if (hasFramePattern(input)) {
      const std::vector<FrameInput> frames = expandInputs({input}, std::nullopt);
      nlohmann::json numbers = nlohmann::json::array();
      for (const auto& f : frames) numbers.push_back(f.frame);
      entry["pattern"] = input;
      entry["frames"] = numbers;
      file = frames.front().files.front();
      if (!a.json) {
        const int first = frames.front().frame, last = frames.back().frame;
        const int gaps = (last - first + 1) - int(frames.size());
        std::printf("%s: %zu frames, %d to %d%s; the first is:\n", input.c_str(), frames.size(), first, last,
                    gaps > 0 ? (" (" + std::to_string(gaps) + " missing in between)").c_str() : "");
      }
    }
    entry["input"] = inspectFile(file, a.headerOnly);
    if (!a.json) printFile(entry["input"]);
    all.push_back(std::move(entry));
  }
  if (a.json) printJson(all);
}

}  // namespace

void addInspectCommand(CLI::App& app) {
  auto args = std::make_shared<InspectArgs>();
  auto* cmd = app.add_subcommand(
      "inspect", "What particle files hold: format, point count, bounds, attributes and their ranges, frames");
  cmd->add_option("inputs", args->inputs, "Particle files or frame patterns (name.$F4.bgeo.sc, name_####.vdb, ...)")
      ->required();
  cmd->add_flag("--json", args->json, "Machine-readable output");
  cmd->add_flag("--header-only", args->headerOnly, "Read the headers only: no bounds, no ranges, at once on any size");
  cmd->callback([args] { runInspect(*args); });
}

}  // namespace flipscope::tools
