// Running a program the way a scheduler's command-line tools are run: argv as given (no shell),
// stdout and stderr captured together.
#pragma once

#include <string>
#include <vector>

namespace flipscope::farm {

struct ProgramRun {
  int exitCode = 0;    ///< 127: the program could not be started; 128 + n: killed by signal n
  std::string output;  ///< stdout and stderr together
};

/// Runs argv[0] (found on PATH) with the arguments, waits for it. Never throws for a failing
/// program: its exit code says so.
ProgramRun runProgram(const std::vector<std::string>& argv);

/// `text` quoted for a POSIX shell (single quotes), unless it is made of safe characters only.
std::string shellQuote(const std::string& text);

}  // namespace flipscope::farm
