// flipscope: previewer for giga-particle fluid caches. See README.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
#include <exception>

#include "core/Error.h"
#include "core/HugePageAdvice.h"
#include "core/ProcessMemory.h"
#include "tools/Commands.h"

int main(int argc, char** argv) {
  using namespace flipscope;
  limitHeapRetention();  // peak RSS within --mem (core/ProcessMemory.h)
  CLI::App app{"flipscope: preview giga-particle fluid simulation caches (Reichl et al. 2014)", "flipscope"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "flipscope 0.1.0");
  tools::addConvertCommand(app);
  tools::addInfoCommand(app);
  tools::addInspectCommand(app);
  tools::addSynthCommand(app);
  tools::addBenchCommand(app);
  tools::addRenderCommand(app);
  tools::addDemoCommand(app);
  tools::addViewCommand(app);
  tools::addFarmCommand(app);
  try {
    // Huge pages where they fill faster, for the commands that allocate large buffers: not for
    // those that read headers (info, inspect), nor --help and --version.
    const bool headersOnly =
        argc < 2 || argv[1][0] == '-' || std::strcmp(argv[1], "info") == 0 || std::strcmp(argv[1], "inspect") == 0;
    if (!headersOnly) chooseHugePageAdvice();
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
