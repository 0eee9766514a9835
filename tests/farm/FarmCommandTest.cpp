// The farm commands without a cluster: --dry-run, refusals with clear messages, and the whole
// flow through stand-in sbatch and squeue that run every job at once, in submission order (a
// scheduler with one infinitely fast node). FarmSlurmTest.cpp runs the same on real Slurm.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "FarmScenarios.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

/// Puts stand-ins for sbatch, squeue, sacct and scontrol first on PATH for the test's lifetime.
class FakeScheduler {
 public:
  FakeScheduler() : mBin("farm-fake-slurm") {
    write("sbatch",
          "#!/bin/bash\n"
          "if [ -n \"${FAKE_SBATCH_FAIL:-}\" ]; then\n"
          "  echo 'sbatch: error: Batch job submission failed: Invalid job array specification' >&2; exit 1\n"
          "fi\n"
          "script=\"${@: -1}\"\n"
          "counter=\"$(dirname \"$0\")/counter\"\n"
          "id=$(( $(cat \"$counter\" 2>/dev/null || echo 100) + 1 ))\n"
          "echo \"$id\" > \"$counter\"\n"
          "last=$(sed -n 's/^#SBATCH --array=0-\\([0-9]*\\)$/\\1/p' \"$script\")\n"
          "log=$(sed -n 's/^#SBATCH --output=//p' \"$script\" | tr -d \"'\")\n"
          "if [ -n \"$last\" ]; then\n"
          "  for i in $(seq 0 \"$last\"); do\n"
          "    SLURM_ARRAY_TASK_ID=$i bash \"$script\" > \"$(echo \"$log\" | sed \"s/%A/$id/; s/%a/$i/\")\" 2>&1\n"
          "  done\n"
          "else\n"
          "  bash \"$script\" > \"$(echo \"$log\" | sed \"s/%j/$id/\")\" 2>&1\n"
          "fi\n"
          "echo \"$id\"\n");
    // FAKE_RUNNING=<job id>: that job is still running.
    write("squeue", "#!/bin/sh\ncase \" $* \" in *\" $FAKE_RUNNING \"*) [ -n \"$FAKE_RUNNING\" ] && echo RUNNING;; esac\nexit 0\n");
    write("sacct", "#!/bin/sh\necho 'Slurm accounting storage is disabled' >&2\nexit 1\n");
    write("scontrol", "#!/bin/sh\nexit 1\n");
    mPath = std::getenv("PATH") ? std::getenv("PATH") : "";
    ::setenv("PATH", (mBin.path().string() + ":" + mPath).c_str(), 1);
  }
  ~FakeScheduler() { ::setenv("PATH", mPath.c_str(), 1); }

 private:
  void write(const std::string& name, const std::string& text) {
    const fs::path file = mBin / name;
    std::ofstream(file) << text;
    fs::permissions(file, fs::perms::owner_all);
  }
  flipscope::testing::TempDir mBin;
  std::string mPath;
};

class FarmCommand : public ::testing::Test {
 protected:
  FakeScheduler scheduler;
  flipscope::testing::FarmScenario scenario{"farm-cli"};
};

TEST_F(FarmCommand, DryRunPrintsEveryScriptAndWritesNothing) {
  const CommandRun dry = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                      scenario.path("s") + " --chunk 3 --mem 2G --time 10:00 --dry-run");
  ASSERT_EQ(dry.exitCode, 0) << dry.output;
  for (const char* expected :
       {"# bounds: sbatch --parsable", "# prepare: sbatch --parsable --dependency=afterok:<bounds job>",
        "# convert: sbatch --parsable --dependency=afterok:<prepare job>",
        "# finalize: sbatch --parsable --dependency=afterany:<convert job>", "#SBATCH --array=0-2",
        "#SBATCH --mem=2G", "#SBATCH --time=10:00", "--append --mem 1740M", "nothing submitted (4 jobs)"})
    EXPECT_NE(dry.output.find(expected), std::string::npos) << expected << "\n" << dry.output;
  EXPECT_FALSE(fs::exists(scenario.path("s")));
  // A number without a unit is MiB, as Slurm reads it.
  const CommandRun mib = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                      scenario.path("s") + " --mem 2000 --dry-run");
  ASSERT_EQ(mib.exitCode, 0) << mib.output;
  EXPECT_NE(mib.output.find("#SBATCH --mem=2000M"), std::string::npos) << mib.output;
  EXPECT_NE(mib.output.find("--append --mem 1700M"), std::string::npos) << mib.output;
  // With a domain: no bounds pass, the domain also clips as in convert.
  const CommandRun domain = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                         scenario.path("s") + " --domain 0,0,0,2,2,2 --dry-run");
  ASSERT_EQ(domain.exitCode, 0) << domain.output;
  EXPECT_EQ(domain.output.find("# bounds:"), std::string::npos) << domain.output;
  EXPECT_NE(domain.output.find("--prepare --domain 0,0,0,2,2,2"), std::string::npos) << domain.output;
  // The particle type attribute goes to the header's convert and to every frame's.
  const CommandRun kinds = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                        scenario.path("s") + " --kind-attribute none --dry-run");
  ASSERT_EQ(kinds.exitCode, 0) << kinds.output;
  EXPECT_NE(kinds.output.find("--prepare --domain \"$domain\" --kind-attribute none"), std::string::npos) << kinds.output;
  EXPECT_NE(kinds.output.find("--append --kind-attribute none"), std::string::npos) << kinds.output;
  // A given particle spacing goes to the header's convert only: the frames' keep the store's.
  const CommandRun spacing = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                          scenario.path("s") + " --particle-spacing 0.125 --dry-run");
  ASSERT_EQ(spacing.exitCode, 0) << spacing.output;
  EXPECT_NE(spacing.output.find("--prepare --domain \"$domain\" --particle-spacing 0.125"), std::string::npos)
      << spacing.output;
  std::size_t given = 0;
  for (auto at = spacing.output.find("--particle-spacing"); at != std::string::npos;
       at = spacing.output.find("--particle-spacing", at + 1))
    ++given;
  EXPECT_EQ(given, 1u) << "the prepare job's only: " << spacing.output;
  // Counts are whole decimal numbers: "09" is 9 frames a task (one task for the 8 frames).
  const CommandRun nine = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " + scenario.path("s") +
                                       " --chunk 09 --dry-run");
  ASSERT_EQ(nine.exitCode, 0) << nine.output;
  EXPECT_NE(nine.output.find("#SBATCH --array=0-0"), std::string::npos) << nine.output;
  const CommandRun fraction = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " +
                                           scenario.path("s") + " --chunk 2.5 --dry-run");
  EXPECT_EQ(fraction.exitCode, 2) << fraction.output;
  EXPECT_NE(fraction.output.find("flipscope: error: --chunk: expected a whole number from 1 to 2147483647, got '2.5'"),
            std::string::npos)
      << fraction.output;
}

TEST_F(FarmCommand, BadRequestsAreRefusedNamingWhatIsWrong) {
  CommandRun c = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " + scenario.path("serial"));
  EXPECT_EQ(c.exitCode, 3) << c.output;
  EXPECT_NE(c.output.find("is a store already"), std::string::npos) << c.output;
  c = runFlipscope("farm convert --resume -o " + scenario.path("nothing"));
  EXPECT_EQ(c.exitCode, 3) << c.output;
  EXPECT_NE(c.output.find(scenario.path("nothing/farm/convert/plan.json")), std::string::npos) << c.output;
  c = runFlipscope("farm convert " + scenario.path("in/none_####.bin") + " -o " + scenario.path("s"));
  EXPECT_NE(c.exitCode, 0) << c.output;
  EXPECT_NE(c.output.find("none_####.bin"), std::string::npos) << c.output;
  c = runFlipscope("farm render " + scenario.path("serial") + " -o " + scenario.path("out.png"));
  EXPECT_EQ(c.exitCode, 2) << c.output;
  EXPECT_NE(c.output.find("needs '#'"), std::string::npos) << c.output;
  c = runFlipscope("farm render " + scenario.path("serial") + " -o " + scenario.path("o_####.png") + " --frames 7-9");
  EXPECT_EQ(c.exitCode, 2) << c.output;
  EXPECT_NE(c.output.find("no frame 9"), std::string::npos) << c.output;
  c = runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " + scenario.path("s") + " --chunk 0");
  EXPECT_EQ(c.exitCode, 2) << c.output;
  c = runFlipscope("farm status 12x");
  EXPECT_EQ(c.exitCode, 2) << c.output;
}

TEST_F(FarmCommand, ConvertEqualsASerialConvert) { scenario.convertEqualsSerial(); }

TEST_F(FarmCommand, ARefusedSubmissionLeavesNothingAndSaysWhy) {
  ::setenv("FAKE_SBATCH_FAIL", "1", 1);
  const CommandRun refused =
      runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " + scenario.path("s"));
  ::unsetenv("FAKE_SBATCH_FAIL");
  EXPECT_EQ(refused.exitCode, 2) << refused.output;
  EXPECT_NE(refused.output.find("Invalid job array specification (an array of 8 tasks: a larger --chunk makes fewer)"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(fs::exists(scenario.path("s")));  // nothing submitted: no plan left to --resume
  const CommandRun again =
      runFlipscope("farm convert " + scenario.path("in/in_####.bin") + " -o " + scenario.path("s") + " --wait");
  EXPECT_EQ(again.exitCode, 0) << again.output;
}

TEST_F(FarmCommand, ResumeIsRefusedWhileTheLastRunStillRuns) {
  scenario.convertEqualsSerial();
  ::setenv("FAKE_RUNNING", "103", 1);  // the third submission: the convert array
  const CommandRun resume = runFlipscope("farm convert --resume -o " + scenario.path("farm"));
  ::unsetenv("FAKE_RUNNING");
  EXPECT_EQ(resume.exitCode, 2) << resume.output;
  EXPECT_NE(resume.output.find("still queued or running: 103"), std::string::npos) << resume.output;
}

TEST_F(FarmCommand, RenderEqualsALocalRender) {
  scenario.convertEqualsSerial();
  scenario.renderEqualsLocal();
}

TEST_F(FarmCommand, AFailedFrameIsNamedAndResumeCompletesTheStore) { scenario.aFailedFrameIsNamedAndResumeCompletes(); }

}  // namespace
