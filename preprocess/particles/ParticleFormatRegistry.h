// The particle file formats flipscope reads and writes: one table (ParticleFormatRegistry.cpp)
// maps each format to its reader, its writer, its file name extensions and its magic bytes.
// An input is recognised by its content: compressed containers (gzip, Houdini's scf1) are
// opened first, then the decoded bytes are matched against each format's magic; the name is
// the fallback for formats without magic (raw floats). Adding a format touches the table, its
// reader's file and its tests.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope {

struct ParticleFormat {
  std::string_view name;         ///< short name: "vdb", "ply", "bgeo", ... (`bench preprocess --format`)
  std::string_view description;  ///< for `inspect` and messages
  /// File name endings, lower case with the dot; compound ones name their container
  /// (".bgeo.sc", ".bgeo.gz"): ".sc" alone is no extension.
  std::vector<std::string_view> extensions;
  /// Whether the first bytes of the (decoded) file are this format's; null: by name only.
  bool (*matches)(std::span<const std::byte> head) = nullptr;
  std::unique_ptr<ParticleSource> (*open)(InputFile file, const ReadOptions& options) = nullptr;
  /// Null when flipscope does not write the format.
  std::unique_ptr<ParticleWriter> (*create)(const std::filesystem::path& path, const WriteOptions& options) = nullptr;
};

/// A compressed container around a particle file, opened before the format is recognised.
struct ContainerFormat {
  std::string_view name;       ///< "gzip", "scf1"
  std::string_view extension;  ///< ".gz", ".sc": stripped from the name for the fallback
  /// Whether `file` is this container (its head and, for footers, its tail).
  bool (*matches)(InputFile& file) = nullptr;
  /// The decoded bytes of `file`; throws FileError for a damaged container.
  std::unique_ptr<ByteSource> (*decode)(InputFile file) = nullptr;
};

/// Every format, in the order magic bytes are tried.
std::span<const ParticleFormat> particleFormats();
std::span<const ContainerFormat> containerFormats();
/// The format named `name` (ParticleFormat::name), or null.
const ParticleFormat* findParticleFormat(std::string_view name);
/// The length of the longest particle format extension the file name `fileName` ends with, in
/// any case (".bgeo.sc" of "Splash.0001.BGEO.SC"); 0 when it ends with none.
std::size_t particleExtensionLength(std::string_view fileName);
/// ".vdb, .ply, ...": every extension once, in the table's order, for messages and help.
std::string supportedExtensions();

/// An opened input: the decoded bytes and what they are.
struct RecognisedInput {
  InputFile file;                   ///< decoded: what the format's reader reads
  const ParticleFormat* format;     ///< never null
  std::vector<std::string> containers;  ///< outermost first, e.g. {"scf1"}
};
/// Recognises `file` (see the file comment). Throws FileError naming the file when nothing
/// matches, listing the formats.
RecognisedInput recogniseInput(InputFile file);

/// openParticleFile() over bytes in memory named `name` (fuzz targets, tests); `bytes` must
/// outlive the source.
std::unique_ptr<ParticleSource> openParticleBytes(const std::filesystem::path& name, std::span<const std::byte> bytes,
                                                  const ReadOptions& options = {});

}  // namespace flipscope
