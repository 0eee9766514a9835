#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "tools/Commands.h"

namespace flipscope::tools {

void addSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "(not yet implemented)");
  cmd->callback([] { throw InputError("synth: not yet implemented"); });
}

}  // namespace flipscope::tools
