// The table of particle formats and containers, and recognition by content (see the header).
#include "preprocess/particles/ParticleFormatRegistry.h"

#include <algorithm>
#include <array>
#include <utility>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope {
namespace {

constexpr std::size_t kHeadBytes = 64;
constexpr int kMaxNestedContainers = 2;  // e.g. a gzip around a gzip is refused beyond this

const std::vector<ParticleFormat>& formatTable() {
  static const std::vector<ParticleFormat> table = {
      {"vdb",
       "OpenVDB points (PointDataGrid)",
       {".vdb"},
       detail::isVdb,
       detail::openVdbPoints,
       detail::createVdbWriter},
      {"ply",
       "PLY polygon file, vertices as points",
       {".ply"},
       detail::isPly,
       detail::openPlyParticles,
       detail::createPlyWriter},
      {"vtk",
       "VTK legacy",
       {".vtk"},
       detail::isVtkLegacy,
       detail::openVtkLegacyParticles,
       detail::createVtkLegacyWriter},
      {"vtu", "VTK XML unstructured grid", {".vtu", ".vtp"}, detail::isVtkXml, detail::openVtkXmlParticles, nullptr},
      {"bgeo",
       "Houdini geometry (binary or ASCII JSON)",
       {".bgeo", ".geo", ".bgeo.sc", ".geo.sc", ".bgeo.gz", ".geo.gz"},
       detail::isHoudiniJson,
       detail::openHoudiniJson,
       detail::createBgeoWriter},
      {"bgeo-classic",
       "Houdini classic geometry (BgeoV / PGEOMETRY)",
       {".bgeo", ".geo", ".bgeo.gz", ".geo.gz"},
       detail::isClassicBgeo,
       detail::openClassicBgeo,
       nullptr},
      {"prt", "Krakatoa PRT particles", {".prt"}, detail::isPrt, detail::openPrtParticles, detail::createPrtWriter},
      {"pdb", "Maya particle disk cache", {".pdb"}, detail::isPdb, detail::openPdbParticles, nullptr},
      // By content only (magic 0xFABADA): a ".bin" name means raw floats, below.
      {"realflow-bin",
       "RealFlow particle cache (.bin, recognised by content)",
       {},
       detail::isRealFlowBin,
       detail::openRealFlowParticles,
       nullptr},
      // No magic: recognised by name only, so it stays last.
      {"raw",
       "raw little-endian float32 xyz",
       {".bin", ".raw"},
       nullptr,
       detail::openRawParticles,
       detail::createRawWriter},
  };
  return table;
}

const std::vector<ContainerFormat>& containerTable() {
  static const std::vector<ContainerFormat> table = {
      {"scf1", ".sc", detail::isScf, detail::decodeScf},
      {"gzip", ".gz", detail::isGzip, detail::decodeGzip},
  };
  return table;
}

std::string lowerName(const std::filesystem::path& path) { return detail::asciiLower(path.filename().string()); }

bool endsWith(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

/// The format whose extension is the longest ending of `name` (lower case), and that
/// extension's length; null and 0 when none is.
std::pair<const ParticleFormat*, std::size_t> longestExtension(std::string_view name) {
  const ParticleFormat* best = nullptr;
  std::size_t bestLength = 0;
  for (const auto& format : formatTable())
    for (auto extension : format.extensions)
      if (endsWith(name, extension) && extension.size() > bestLength) {
        best = &format;
        bestLength = extension.size();
      }
  return {best, bestLength};
}

/// The format whose extension is the longest ending of `name` (lower case), or null.
const ParticleFormat* formatByName(const std::string& name) { return longestExtension(name).first; }

}  // namespace

std::size_t particleExtensionLength(std::string_view fileName) {
  return longestExtension(detail::asciiLower(fileName)).second;
}

std::span<const ParticleFormat> particleFormats() { return formatTable(); }
std::span<const ContainerFormat> containerFormats() { return containerTable(); }

const ParticleFormat* findParticleFormat(std::string_view name) {
  for (const auto& format : formatTable())
    if (format.name == name) return &format;
  return nullptr;
}

std::string supportedExtensions() {
  // Formats that share an ending (modern and classic Houdini's .bgeo, .geo, .bgeo.gz, .geo.gz;
  // RealFlow's and raw .bin) list it once.
  std::vector<std::string_view> listed;
  std::string list;
  for (const auto& format : formatTable())
    for (auto extension : format.extensions) {
      if (std::find(listed.begin(), listed.end(), extension) != listed.end()) continue;
      listed.push_back(extension);
      list += (list.empty() ? "" : ", ") + std::string(extension);
    }
  return list;
}

RecognisedInput recogniseInput(InputFile file) {
  std::vector<std::string> containers;
  std::string name = lowerName(file.path());
  for (int depth = 0;; ++depth) {
    const ContainerFormat* container = nullptr;
    for (const auto& candidate : containerTable())
      if (candidate.matches(file)) container = &candidate;
    if (!container) break;
    if (depth == kMaxNestedContainers)
      throw FileError(file.path(), "more than " + std::to_string(kMaxNestedContainers) + " nested compressed containers");
    containers.emplace_back(container->name);
    if (endsWith(name, container->extension) && !formatByName(name)) name.resize(name.size() - container->extension.size());
    std::filesystem::path path = file.path();
    file = InputFile(path, container->decode(std::move(file)));
  }
  const std::vector<std::byte> head = file.peekHead(kHeadBytes);
  for (const auto& format : formatTable())
    if (format.matches && format.matches(head)) return {std::move(file), &format, std::move(containers)};
  // By name: the format's reader then says what is wrong with the file ("bad magic", ...).
  if (const ParticleFormat* format = formatByName(name)) return {std::move(file), format, std::move(containers)};
  if (file.size() == 0) throw FileError(file.path(), "is empty (0 bytes), expected a particle file");
  throw FileError(file.path(), "unknown particle file format (supported: " + supportedExtensions() + ")");
}

std::unique_ptr<ParticleSource> openParticleFile(const std::filesystem::path& path, const ReadOptions& options) {
  RecognisedInput input = recogniseInput(InputFile(path, options.readOnceAheadBytes));
  return input.format->open(std::move(input.file), options);
}

std::unique_ptr<ParticleSource> openParticleBytes(const std::filesystem::path& name, std::span<const std::byte> bytes,
                                                  const ReadOptions& options) {
  RecognisedInput input = recogniseInput(InputFile(name, bytes));
  return input.format->open(std::move(input.file), options);
}

std::unique_ptr<ParticleWriter> createParticleWriter(const std::filesystem::path& path, const WriteOptions& options) {
  const ParticleFormat* format = formatByName(lowerName(path));
  if (!format || !format->create) {
    std::string writable;
    for (const auto& f : formatTable())
      if (f.create)
        for (auto extension : f.extensions)
          if (!endsWith(extension, ".gz"))  // no writer writes gzip
            writable += (writable.empty() ? "" : ", ") + std::string(extension);
    throw FileError(path, "cannot write this particle format (writable: " + writable + ")");
  }
  return format->create(path, options);
}

}  // namespace flipscope
