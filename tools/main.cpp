// flipscope: previewer for giga-particle fluid caches. See README.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "core/Error.h"
#include "core/HugePageAdvice.h"
#include "core/ProcessMemory.h"
#include "tools/CliChecks.h"
#include "tools/Commands.h"

namespace {

/// Whether the parsed command (its subcommand path, as "farm status") is one that allocates
/// large buffers: all but info, inspect, devices and the farm's submission, status and finalize.
bool allocatesLargeBuffers(const CLI::App& app) {
  std::string path;
  for (const CLI::App* c = &app; !c->get_subcommands().empty();) {
    c = c->get_subcommands().front();
    path += (path.empty() ? "" : " ") + c->get_name();
  }
  for (const char* light :
       {"info", "inspect", "devices", "farm convert", "farm render", "farm status", "farm finalize"})
    if (path == light) return false;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace flipscope;
  limitHeapRetention();  // peak RSS within --mem (core/ProcessMemory.h)
  CLI::App app{"flipscope: preview giga-particle fluid simulation caches (Reichl et al. 2014)", "flipscope"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "flipscope 0.1.0");
  // A usage error reads as every other error does ("flipscope: error: ..."), exit 2.
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return std::string("flipscope: error: ") + e.what() + "\nRun with --help for more information.\n";
  });
  tools::addConvertCommand(app);
  tools::addInfoCommand(app);
  tools::addInspectCommand(app);
  tools::addSynthCommand(app);
  tools::addBenchCommand(app);
  tools::addRenderCommand(app);
  tools::addDemoCommand(app);
  tools::addViewCommand(app);
  tools::addFarmCommand(app);
  tools::addDevicesCommand(app);
  tools::readIntegersInDecimal(app);
  // Huge pages where they fill faster (core/HugePageAdvice.h), chosen once the command line has
  // parsed (not for --help, --version or a usage error) and before the command runs, for the
  // commands that allocate large buffers: not for those that read headers or submit jobs.
  app.parse_complete_callback([&app] {
    if (allocatesLargeBuffers(app)) chooseHugePageAdvice();
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "flipscope: error: %s\n", e.what());
    return kExitOutput;
  } catch (const FileError& e) {
    std::fprintf(stderr, "flipscope: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "flipscope: error: %s\n", e.what());
    return kExitUsage;
  } catch (const tools::CommandFailed& e) {
    std::fprintf(stderr, "flipscope: %s\n", e.what());
    return e.exitCode();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "flipscope: internal error: %s\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}
