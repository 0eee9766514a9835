// Checks of numeric command-line options, with messages a user reads: CLI11's own ranges print
// the largest double in full ("not in range 0.000000 to 1797693134862315...").
#pragma once

#include <CLI/CLI.hpp>

namespace flipscope::tools {

/// A finite number above 0 ("--cell-size: expected a number above 0, got 'abc'").
CLI::Validator positiveNumber();
/// A whole number from 1 to 2^31 - 1, for counts ("--cpus: expected a whole number above 0, got '1.5'").
CLI::Validator positiveCount();
/// A finite number of 0 or more ("--particle-spacing: expected a number of 0 or more, got '-1'").
CLI::Validator nonNegativeNumber();

}  // namespace flipscope::tools
