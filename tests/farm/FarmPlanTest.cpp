// The farm library without a scheduler: chunks, plans, job scripts and their dependencies,
// shell quoting, summaries that name the failed frames.
#include <gtest/gtest.h>

#include <fstream>

#include "TestSupport.h"
#include "core/Error.h"
#include "tools/farm/FarmJobs.h"
#include "tools/farm/FarmPlan.h"
#include "tools/farm/FarmSummary.h"
#include "tools/farm/RunProgram.h"

namespace {

using namespace flipscope::farm;
namespace fs = std::filesystem;

FarmPlan convertPlan(const fs::path& store) {
  FarmPlan p;
  p.kind = FarmKind::Convert;
  p.store = store;
  p.flipscope = "/opt/flip scope/flipscope";
  p.frames = {1, 2, 3, 4, 5, 7, 8};
  p.chunk = 3;
  p.inputs = {"/data/it's here/in_####.bgeo.sc"};
  p.prepareArgs = {"--cell-size", "0.25"};
  p.convertArgs = {"--mem", "1G"};
  p.boundsPass = true;
  p.resources = {"gpu", "1:00:00", 4, "2G"};
  return p;
}

TEST(FarmPlan, ChunksAreConsecutiveAndCoverEveryFrame) {
  EXPECT_EQ(chunkFrames({1, 2, 3, 4, 5, 7, 8}, 3), (std::vector<std::vector<int>>{{1, 2, 3}, {4, 5, 7}, {8}}));
  EXPECT_EQ(chunkFrames({4}, 10), (std::vector<std::vector<int>>{{4}}));
  EXPECT_TRUE(chunkFrames({}, 2).empty());
}

TEST(FarmPlan, SavedPlansReadBackAndDamagedOnesAreNamed) {
  flipscope::testing::TempDir temp("farm-plan");
  FarmPlan p = convertPlan(temp / "store");
  p.grids = {"flip", "spray"};
  savePlan(p);
  const FarmPlan back = loadPlan(p.store, FarmKind::Convert);
  EXPECT_EQ(back.frames, p.frames);
  EXPECT_EQ(back.inputs, p.inputs);
  EXPECT_EQ(back.grids, p.grids);
  EXPECT_EQ(back.prepareArgs, p.prepareArgs);
  EXPECT_EQ(back.resources.memory, "2G");
  EXPECT_EQ(back.resources.cpus, 4);
  EXPECT_THROW(loadPlan(p.store, FarmKind::Render), flipscope::FileError);  // no render planned
  std::ofstream(farmDirectory(p.store, FarmKind::Convert) / "plan.json") << "{\"kind\": \"convert\"";
  try {
    loadPlan(p.store, FarmKind::Convert);
    FAIL() << "a damaged plan was read";
  } catch (const flipscope::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("plan.json"), std::string::npos) << e.what();
  }
}

TEST(FarmPlan, SubmissionsAccumulate) {
  flipscope::testing::TempDir temp("farm-jobs");
  EXPECT_TRUE(loadSubmissions(temp.path()).empty());
  appendSubmissions(temp.path(), {{"convert", "12", {{1, 2}, {3}}}});
  appendSubmissions(temp.path(), {{"finalize", "13", {}}});
  const auto all = loadSubmissions(temp.path());
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].tasks, (std::vector<std::vector<int>>{{1, 2}, {3}}));
  EXPECT_EQ(all[1].job, "13");
}

TEST(FarmJobs, ConvertIsBoundsThenPrepareThenTheArrayThenFinalize) {
  const FarmPlan p = convertPlan("/farm/store");
  auto slurm = makeSlurmScheduler();
  const auto jobs = planJobs(p, p.frames, true, *slurm);
  ASSERT_EQ(jobs.size(), 4u);
  EXPECT_EQ(jobs[0].role, "bounds");
  EXPECT_EQ(jobs[1].role, "prepare");
  EXPECT_EQ(jobs[1].request.afterOk, std::vector<std::string>{"bounds"});
  EXPECT_EQ(jobs[2].role, "convert");
  EXPECT_EQ(jobs[2].request.afterOk, std::vector<std::string>{"prepare"});
  EXPECT_EQ(jobs[2].request.tasks, 3);
  EXPECT_EQ(jobs[3].role, "finalize");
  EXPECT_EQ(jobs[3].request.afterAny, std::vector<std::string>{"convert"});
  const std::string& convert = jobs[2].script;
  EXPECT_NE(convert.find("#SBATCH --array=0-2\n"), std::string::npos) << convert;
  EXPECT_NE(convert.find("#SBATCH --partition=gpu\n#SBATCH --time=1:00:00\n#SBATCH --cpus-per-task=4\n"
                         "#SBATCH --mem=2G\n"),
            std::string::npos)
      << convert;
  EXPECT_NE(convert.find("  \"1 2 3\"\n  \"4 5 7\"\n  \"8\"\n"), std::string::npos) << convert;
  EXPECT_NE(convert.find("flipscope='/opt/flip scope/flipscope'"), std::string::npos) << convert;
  EXPECT_NE(convert.find("'/data/it'\\''s here/in_####.bgeo.sc' --frames \"$frame\" -o \"$store\" --append --mem 1G"),
            std::string::npos)
      << convert;
  EXPECT_NE(jobs[1].script.find("--prepare --domain \"$domain\" --cell-size 0.25"), std::string::npos)
      << jobs[1].script;
  // The commands: dependencies, and cancellation when an afterok dependency fails.
  const auto command = slurm->submitCommand(jobs[1].request);
  EXPECT_EQ(command[2], "--dependency=afterok:bounds");
  EXPECT_EQ(command[3], "--kill-on-invalid-dep=yes");
  // A resume of a store whose header exists: only the array and the summary.
  const auto resume = planJobs(p, {5}, false, *slurm);
  ASSERT_EQ(resume.size(), 2u);
  EXPECT_TRUE(resume[0].request.afterOk.empty());
  EXPECT_EQ(resume[0].tasks, (std::vector<std::vector<int>>{{5}}));
}

TEST(FarmJobs, AGivenDomainNeedsNoBoundsPass) {
  FarmPlan p = convertPlan("/farm/store");
  p.boundsPass = false;
  auto slurm = makeSlurmScheduler();
  const auto jobs = planJobs(p, p.frames, true, *slurm);
  ASSERT_EQ(jobs.size(), 3u);
  EXPECT_EQ(jobs[0].role, "prepare");
  EXPECT_TRUE(jobs[0].request.afterOk.empty());
  EXPECT_EQ(jobs[0].script.find("farm bounds"), std::string::npos) << jobs[0].script;
}

TEST(FarmJobs, TheScriptsRunInBashAndLoopOverTheirFrames) {
  // The convert job's script with a stand-in flipscope that fails on frame 4: every other frame
  // runs, frame 4's error lands in failed/frame_000004.log, the task exits 1.
  flipscope::testing::TempDir temp("farm-script");
  FarmPlan p = convertPlan(temp / "store");
  p.flipscope = temp / "fake-flipscope";
  std::ofstream(p.flipscope) << "#!/bin/sh\n"
                                "echo \"$@\" >> " << (temp / "calls").string() << "\n"
                                "case \"$*\" in *\"--frames 4 \"*) echo 'flipscope: error: in_0004: truncated' >&2; exit 3;; esac\n";
  fs::permissions(p.flipscope, fs::perms::owner_all);
  auto slurm = makeSlurmScheduler();
  const auto jobs = planJobs(p, p.frames, false, *slurm);
  const fs::path script = temp / "convert.sh";
  std::ofstream(script) << jobs[0].script;
  const auto run = runProgram({"env", "SLURM_ARRAY_TASK_ID=1", "bash", script.string()});
  EXPECT_EQ(run.exitCode, 1) << run.output;
  std::ifstream calls(temp / "calls");
  std::string text((std::istreambuf_iterator<char>(calls)), {});
  for (int f : {4, 5, 7}) EXPECT_NE(text.find("--frames " + std::to_string(f) + " "), std::string::npos) << text;
  EXPECT_EQ(text.find("--frames 1 "), std::string::npos) << text;
  std::ifstream log(farmDirectory(p.store, FarmKind::Convert) / "failed" / "frame_000004.log");
  std::string logged((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(logged.find("flipscope: error: in_0004: truncated"), std::string::npos) << logged;
  EXPECT_FALSE(fs::exists(farmDirectory(p.store, FarmKind::Convert) / "failed" / "frame_000005.log"));
  // The summary names the failed frame by the error its task wrote, and the one without result.
  const FarmSummary s = summarize(
      p, [](int frame) { return FrameCheck{frame != 4 && frame != 8, ""}; }, "no result");
  ASSERT_EQ(s.missing.size(), 2u);
  EXPECT_EQ(s.missing[0].frame, 4);
  EXPECT_EQ(s.missing[0].reason, "flipscope: error: in_0004: truncated");
  EXPECT_EQ(s.missing[1].reason, "no result");
  const std::string text2 = summaryText(s, p);
  EXPECT_NE(text2.find("5 of 7 frames done, 2 missing or failed"), std::string::npos) << text2;
  EXPECT_NE(text2.find("frame 4: flipscope: error: in_0004: truncated"), std::string::npos) << text2;
  EXPECT_NE(text2.find("--resume"), std::string::npos) << text2;
}

TEST(RunProgram, QuotesWhatTheShellWouldSplit) {
  EXPECT_EQ(shellQuote("plain/path-1.2_x"), "plain/path-1.2_x");
  EXPECT_EQ(shellQuote("a b"), "'a b'");
  EXPECT_EQ(shellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(shellQuote(""), "''");
  EXPECT_EQ(shellQuote("in_####.bin"), "'in_####.bin'");
  const auto run = runProgram({"sh", "-c", "echo " + shellQuote("it's $HOME `x`")});
  EXPECT_EQ(run.output, "it's $HOME `x`\n");
  EXPECT_EQ(runProgram({"/no/such/program"}).exitCode, 127);
}

}  // namespace
