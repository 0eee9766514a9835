#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "(not yet implemented)");
  cmd->callback([] { throw InputError("info: not yet implemented"); });
}

}  // namespace flipscope::tools
