#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addBenchRenderCommand(CLI::App& bench) {
  auto* cmd = bench.add_subcommand("render", "(not yet implemented)");
  cmd->callback([] { throw InputError("render: not yet implemented"); });
}

}  // namespace flipscope::tools
