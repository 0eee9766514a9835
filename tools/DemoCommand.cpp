#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addDemoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "(not yet implemented)");
  cmd->callback([] { throw InputError("demo: not yet implemented"); });
}

}  // namespace flipscope::tools
