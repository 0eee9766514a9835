// Parsing of command-line values shared by the subcommands: sizes with suffixes, boxes.
// Every parser throws InputError naming the option and the text it could not read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "core/Box.h"
#include "core/UpAxis.h"
#include "preprocess/store/BrickStore.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope::tools {

/// "1000", "10k", "2.5M", "1G" (powers of 1000) -> count.
std::uint64_t parseCount(const std::string& option, const std::string& text);
/// "512M", "4G", "64MiB", "1073741824" (k/M/G and KiB/MiB/GiB are powers of 1024) -> bytes.
std::uint64_t parseBytes(const std::string& option, const std::string& text);
/// "x0,y0,z0,x1,y1,z1" -> box with min <= max.
Box parseBox(const std::string& option, const std::string& text);
/// "1920x1080" -> {1920, 1080}; both at least 1.
std::pair<std::uint32_t, std::uint32_t> parseImageSize(const std::string& option, const std::string& text);
/// "auto", "gpu" or "cpu" (the `--device` of render, demo and bench render).
DeviceChoice parseDeviceChoice(const std::string& option, const std::string& text);
/// `--up`: "x", "y" or "z"; "auto" (nullopt): what the store or the input files say.
std::optional<UpAxis> parseUpAxis(const std::string& option, const std::string& text);
/// A box as parseBox reads it, every number read back exactly (exactNumberText).
std::string formatBox(const Box& box);
/// "none", "speed (the length of the velocity)", "pscale (scalar)", "v (the length of a vector)".
std::string describeAttribute(const StoreHeader& header);
/// The cells of each particle kind: "liquid 120, foam 3, spray 40, bubble 0".
std::string describeKindCells(const std::array<std::uint64_t, kParticleKindCount>& cells);

}  // namespace flipscope::tools
