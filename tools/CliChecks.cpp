#include "tools/CliChecks.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>

namespace flipscope::tools {
namespace {

/// The whole text as a finite number; nullopt for anything else (words, nan, inf, overflow).
std::optional<double> finiteNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) return std::nullopt;
  return value;
}

CLI::Validator numberCheck(bool zeroAllowed) {
  const std::string expected = zeroAllowed ? "a number of 0 or more" : "a number above 0";
  return CLI::Validator(
      [zeroAllowed, expected](std::string& text) -> std::string {
        const auto value = finiteNumber(text);
        if (value && (*value > 0 || (zeroAllowed && *value == 0))) return {};
        return "expected " + expected + ", got '" + text + "'";
      },
      zeroAllowed ? "NONNEGATIVE" : "POSITIVE");
}

}  // namespace

CLI::Validator positiveNumber() { return numberCheck(false); }

CLI::Validator positiveCount() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const auto value = finiteNumber(text);
        if (value && *value >= 1 && *value <= std::numeric_limits<std::int32_t>::max() && *value == std::floor(*value) &&
            text.find_first_not_of("+0123456789") == std::string::npos)
          return {};
        return "expected a whole number above 0, got '" + text + "'";
      },
      "POSITIVE");
}

CLI::Validator nonNegativeNumber() { return numberCheck(true); }

}  // namespace flipscope::tools
