#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addBenchPreprocessCommand(CLI::App& bench) {
  auto* cmd = bench.add_subcommand("preprocess", "(not yet implemented)");
  cmd->callback([] { throw InputError("preprocess: not yet implemented"); });
}

}  // namespace flipscope::tools
