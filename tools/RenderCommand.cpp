#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addRenderCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "(not yet implemented)");
  cmd->callback([] { throw InputError("render: not yet implemented"); });
}

}  // namespace flipscope::tools
