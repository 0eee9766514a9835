#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addBenchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "(not yet implemented)");
  cmd->callback([] { throw InputError("bench: not yet implemented"); });
}

}  // namespace flipscope::tools
