#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addConvertCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert", "(not yet implemented)");
  cmd->callback([] { throw InputError("convert: not yet implemented"); });
}

}  // namespace flipscope::tools
