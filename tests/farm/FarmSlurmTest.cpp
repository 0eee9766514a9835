// The farm on a real Slurm: tests/farm/run-slurm.sh starts a one-node cluster (munged,
// slurmctld, slurmd) and runs these with SLURM_CONF set; CI requires them
// (FLIPSCOPE_REQUIRE_SLURM=1). The scenarios are those of FarmScenarios.h; farm status reads
// the tasks back from the scheduler.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "FarmScenarios.h"
#include "TestSupport.h"

namespace {

using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

class FarmSlurm : public ::testing::Test {
 protected:
  void SetUp() override {
    const bool cluster = std::getenv("FLIPSCOPE_SLURM") && std::getenv("SLURM_CONF");
    if (!cluster) {
      if (std::getenv("FLIPSCOPE_REQUIRE_SLURM"))
        FAIL() << "no Slurm cluster: run through tests/farm/run-slurm.sh";
      GTEST_SKIP() << "no Slurm cluster (tests/farm/run-slurm.sh starts one)";
    }
  }
};

TEST_F(FarmSlurm, ConvertThenRenderMatchSerialAndLocal) {
  flipscope::testing::FarmScenario scenario("farm-slurm");
  scenario.convertEqualsSerial();
  const CommandRun status = runFlipscope("farm status " + scenario.path("farm"));
  EXPECT_EQ(status.exitCode, 0) << status.output;
  for (const char* expected : {"flipscope-bounds", "flipscope-prepare", "flipscope-convert", "flipscope-finalize",
                               "COMPLETED", "8 of 8 frames done, complete"})
    EXPECT_NE(status.output.find(expected), std::string::npos) << expected << "\n" << status.output;
  scenario.renderEqualsLocal();
}

TEST_F(FarmSlurm, AFailedFrameIsNamedAndResumeCompletesTheStore) {
  flipscope::testing::FarmScenario scenario("farm-slurm-fail");
  scenario.aFailedFrameIsNamedAndResumeCompletes();
  const CommandRun status = runFlipscope("farm status " + scenario.path("resumed"));
  EXPECT_NE(status.output.find("FAILED"), std::string::npos) << status.output;  // the first convert's task
}

}  // namespace
