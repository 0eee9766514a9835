// The flipscope subcommands. Each add*Command() registers its options on `app` and its
// callback; callbacks throw InputError/FileError for bad input (main() maps them to exit codes)
// and return normally on success. A command that must report failure otherwise (e.g. a store
// that fails --verify) throws CommandFailed.
#pragma once

#include <stdexcept>
#include <string>

namespace CLI {
class App;
}

namespace flipscope::tools {

/// A command finished and printed its findings but must exit with `exitCode` (kExitFailure,
/// or kExitNotConverged for a render that stopped at its pass limit).
class CommandFailed : public std::runtime_error {
 public:
  explicit CommandFailed(const std::string& message, int exitCode = 1)
      : std::runtime_error(message), mExitCode(exitCode) {}
  int exitCode() const { return mExitCode; }

 private:
  int mExitCode;
};

void addConvertCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addInspectCommand(CLI::App& app);
void addSynthCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);  // creates `bench` and calls the ones below
void addRenderCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addDevicesCommand(CLI::App& app);
void addFarmCommand(CLI::App& app);  // farm convert | render | status, and the tasks' bounds, finalize

// `flipscope bench <stage>`: each in its own file (tools/Bench<Stage>.cpp).
void addBenchPreprocessCommand(CLI::App& bench);
void addBenchStreamingCommand(CLI::App& bench);
void addBenchRenderCommand(CLI::App& bench);
void addBenchSurfaceCommand(CLI::App& bench);
void addBenchFarmCommand(CLI::App& bench);
void addBenchViewCommand(CLI::App& bench);
void addBenchScaleCommand(CLI::App& bench);

}  // namespace flipscope::tools
