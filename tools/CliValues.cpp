#include "tools/CliValues.h"

#include <charconv>
#include <cmath>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/Error.h"
#include "core/NumberText.h"

namespace flipscope::tools {
namespace {

[[noreturn]] void bad(const std::string& option, const std::string& text, const std::string& expected) {
  throw InputError(option + ": cannot read '" + text + "', expected " + expected);
}

/// Splits "2.5M" into 2.5 and "M".
std::pair<double, std::string> numberAndSuffix(const std::string& option, const std::string& text,
                                               const std::string& expected) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    bad(option, text, expected);
  }
  if (!std::isfinite(value) || value < 0) bad(option, text, expected);
  return {value, text.substr(used)};
}

}  // namespace

std::uint64_t parseCount(const std::string& option, const std::string& text) {
  const char* expected = "a count such as 1000, 10k, 2.5M or 1G";
  auto [value, suffix] = numberAndSuffix(option, text, expected);
  double scale = 1;
  if (suffix == "k" || suffix == "K")
    scale = 1e3;
  else if (suffix == "M" || suffix == "m")
    scale = 1e6;
  else if (suffix == "G" || suffix == "g")
    scale = 1e9;
  else if (!suffix.empty())
    bad(option, text, expected);
  const double count = std::round(value * scale);
  if (count > 1e15) bad(option, text, expected);
  return std::uint64_t(count);
}

std::uint64_t parseBytes(const std::string& option, const std::string& text) {
  const char* expected = "a size such as 512M, 4G or 64MiB";
  auto [value, suffix] = numberAndSuffix(option, text, expected);
  double scale = 1;
  if (suffix == "k" || suffix == "K" || suffix == "KiB" || suffix == "kB")
    scale = 1024.0;
  else if (suffix == "M" || suffix == "MiB" || suffix == "MB")
    scale = 1024.0 * 1024;
  else if (suffix == "G" || suffix == "GiB" || suffix == "GB")
    scale = 1024.0 * 1024 * 1024;
  else if (!suffix.empty() && suffix != "B")
    bad(option, text, expected);
  const double bytes = std::round(value * scale);
  if (bytes < 1 || bytes > 1e18) bad(option, text, expected);
  return std::uint64_t(bytes);
}

Box parseBox(const std::string& option, const std::string& text) {
  const char* expected = "six numbers x0,y0,z0,x1,y1,z1";
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(v.back())) bad(option, text, expected);
    } catch (const std::logic_error&) {
      bad(option, text, expected);
    }
  }
  if (v.size() != 6) bad(option, text, expected);
  Box box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  if (box.isEmpty()) bad(option, text, "min <= max on every axis");
  return box;
}

std::pair<std::uint32_t, std::uint32_t> parseImageSize(const std::string& option, const std::string& text) {
  constexpr std::uint64_t kMaxSide = 32768;  // a 1 Gpixel image at most: beyond, buffers cannot be allocated
  const std::string expected = "WxH with sides 1 to " + std::to_string(kMaxSide) + ", e.g. 1920x1080";
  const auto cross = text.find_first_of("xX");
  if (cross == std::string::npos) bad(option, text, expected);
  auto side = [&](std::string_view digits) {
    std::uint64_t value = 0;
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || value == 0 || value > kMaxSide)
      bad(option, text, expected);
    return std::uint32_t(value);
  };
  const std::string_view all(text);
  return {side(all.substr(0, cross)), side(all.substr(cross + 1))};
}

DeviceChoice parseDeviceChoice(const std::string& option, const std::string& text) {
  if (text == "auto") return DeviceChoice::Auto;
  if (text == "gpu") return DeviceChoice::Gpu;
  if (text == "cpu") return DeviceChoice::Cpu;
  if (text == "cpu-reference") return DeviceChoice::CpuReference;
  bad(option, text, "auto, gpu, cpu or cpu-reference");
}

std::string describeKindCells(const std::array<std::uint64_t, kParticleKindCount>& cells) {
  std::string text;
  for (std::size_t k = 0; k < kParticleKindCount; ++k)
    text += (k ? ", " : "") + std::string(particleKindName(ParticleKind(k))) + " " + std::to_string(cells[k]);
  return text;
}

std::string describeAttribute(const StoreHeader& header) {
  switch (header.attribute) {
    case AttributeKind::None:
      return "none";
    case AttributeKind::Speed:
      return "speed (the length of the velocity)";
    case AttributeKind::Scalar:
      return header.attributeName + " (scalar)";
    case AttributeKind::Magnitude:
      return header.attributeName + " (the length of a vector)";
  }
  return header.attributeName;
}

std::optional<UpAxis> parseUpAxis(const std::string& option, const std::string& text) {
  if (text == "auto") return std::nullopt;
  if (const auto axis = parseUpAxisName(text)) return axis;
  throw InputError(option + ": expected auto, x, y or z, got '" + text + "'");
}

std::string formatBox(const Box& box) {
  std::string text;
  for (double v : {box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z})
    text += (text.empty() ? "" : ",") + exactNumberText(v);
  return text;
}

}  // namespace flipscope::tools
