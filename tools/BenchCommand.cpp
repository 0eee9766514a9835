#include <CLI/CLI.hpp>

#include "tools/BenchFrameStage.h"
#include "tools/Commands.h"
#include "tools/EmbreePeer.h"

namespace flipscope::tools {

void addBenchCommand(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Benchmarks, printed as tables with the comparison in the same run");
  bench->require_subcommand(1);
  addBenchPreprocessCommand(*bench);
  addBenchStreamingCommand(*bench);
  addBenchRenderCommand(*bench);
  addBenchSurfaceCommand(*bench);
  addBenchFarmCommand(*bench);
  addBenchViewCommand(*bench);
  addBenchScaleCommand(*bench);
  addBenchFrameStageCommand(*bench);
  addBenchEmbreeStageCommand(*bench);
}

}  // namespace flipscope::tools
