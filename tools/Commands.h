// The flipscope subcommands. Each add*Command() registers its options on `app` and its
// callback; callbacks throw InputError/FileError for bad input (main() maps them to exit codes)
// and return normally on success. A command that must report failure otherwise (e.g. a store
// that fails --verify) throws CommandFailed.
#pragma once

#include <stdexcept>

namespace CLI {
class App;
}

namespace flipscope::tools {

/// A command finished and printed its findings but must exit with kExitFailure.
class CommandFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void addConvertCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addSynthCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);

}  // namespace flipscope::tools
