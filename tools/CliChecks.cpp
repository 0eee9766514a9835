#include "tools/CliChecks.h"

#include <cerrno>
#include <charconv>
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

/// positiveNumber() (zeroAllowed false) or nonNegativeNumber() (true).
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
        // Decimal digits, an optional '+' first.
        const char* first = text.data() + (text.starts_with('+') ? 1 : 0);
        const char* last = text.data() + text.size();
        std::int64_t value = 0;
        const auto [end, error] = std::from_chars(first, last, value);
        if (first == last || error != std::errc() || end != last || value < 1 ||
            value > std::numeric_limits<std::int32_t>::max())
          return "expected a whole number from 1 to " + std::to_string(std::numeric_limits<std::int32_t>::max()) +
                 ", got '" + text + "'";
        return {};
      },
      "POSITIVE");
}

void readIntegersInDecimal(CLI::App& app) {
  // Drops the leading zeros of a signed decimal integer ("-010" -> "-10"); other text ("0",
  // "0x10", "abc") is left to the option's own checks and conversion.
  const CLI::Validator decimal(
      [](std::string& text) -> std::string {
        const std::size_t digits = text.starts_with('+') || text.starts_with('-') ? 1 : 0;
        const std::size_t significant = text.find_first_not_of('0', digits);
        if (significant > digits && significant != std::string::npos &&
            text.find_first_not_of("0123456789", digits) == std::string::npos)
          text.erase(digits, significant - digits);
        return {};
      },
      "");
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.starts_with("INT") || type.starts_with("UINT")) option->transform(decimal);
  }
  for (CLI::App* subcommand : app.get_subcommands([](CLI::App*) { return true; })) readIntegersInDecimal(*subcommand);
}

CLI::Validator nonNegativeNumber() { return numberCheck(true); }

}  // namespace flipscope::tools
