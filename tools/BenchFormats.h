// The reader part of `flipscope bench preprocess` (issue 11): the same synth particles written
// in each format, then read back through the registry's reader, beside the raw-float read of
// the same particles; and convert's peak RSS per format against --mem (issue 12), each in a
// child `flipscope convert` so that one format's peak does not hide another's.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace flipscope::tools {

struct FormatBenchOptions {
  std::vector<std::string> formats;  ///< file extensions without the dot: "bgeo.sc", "prt", "vtk", "ply", "vdb", ...
  std::uint64_t particles = 0;
  std::string mem = "64M";           ///< --mem of the child converts
  std::filesystem::path workDir;     ///< synth files are written (and reused) here
};

/// Runs the benchmark; returns {"formats": [...], "raw_read_particles_per_s": ...}.
nlohmann::json benchFormats(const FormatBenchOptions& options);
/// The table of benchFormats()'s result.
void printFormatTable(const nlohmann::json& result, const FormatBenchOptions& options);

}  // namespace flipscope::tools
