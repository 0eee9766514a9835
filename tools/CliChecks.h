// Checks of numeric command-line options, with messages a user reads: CLI11's own ranges print
// the largest double in full ("not in range 0.000000 to 1797693134862315...").
#pragma once

#include <CLI/CLI.hpp>

namespace flipscope::tools {

/// A finite number above 0 ("--cell-size: expected a number above 0, got 'abc'").
CLI::Validator positiveNumber();
/// A whole number from 1 to 2^31 - 1 in decimal, for counts ("--cpus: expected a whole number from 1
/// to 2147483647, got '1.5'"); "+8" and "010" are 8 and 10 (with readIntegersInDecimal).
CLI::Validator positiveCount();
/// Makes every integer option of `app` and of its subcommands, at any depth, read "010" as 10:
/// CLI11 reads integers in base 0, where a leading zero means octal ("--frame 010" was frame 8).
/// Call once every option is added.
void readIntegersInDecimal(CLI::App& app);
/// A finite number of 0 or more ("--particle-spacing: expected a number of 0 or more, got '-1'").
CLI::Validator nonNegativeNumber();

}  // namespace flipscope::tools
