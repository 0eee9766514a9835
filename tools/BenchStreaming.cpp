#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addBenchStreamingCommand(CLI::App& bench) {
  auto* cmd = bench.add_subcommand("streaming", "(not yet implemented)");
  cmd->callback([] { throw InputError("streaming: not yet implemented"); });
}

}  // namespace flipscope::tools
