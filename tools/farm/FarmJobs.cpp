#include "tools/farm/FarmJobs.h"

#include <map>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "tools/farm/RunProgram.h"

namespace flipscope::farm {
namespace {

std::string words(const std::vector<std::string>& items) {
  std::string text;
  for (const auto& item : items) text += " " + shellQuote(item);
  return text;
}

std::string frameList(const std::vector<int>& frames) {
  std::string text;
  for (int f : frames) text += (text.empty() ? "" : " ") + std::to_string(f);
  return text;
}

/// The script's start: directives, what it is, the variables every body uses.
std::string preamble(const FarmPlan& plan, const FarmJob& job, const Scheduler& scheduler) {
  const auto farm = farmDirectory(plan.store, plan.kind);
  std::string text = "#!/bin/bash\n" + scheduler.directives(job.request);
  text += "# flipscope farm " + std::string(farmKindName(plan.kind)) + ": the " + job.role +
          " job (written by flipscope; the plan is " + (farm / "plan.json").string() + ")\n";
  text += "set -u\n";
  text += "flipscope=" + shellQuote(plan.flipscope.string()) + "\n";
  text += "store=" + shellQuote(plan.store.string()) + "\n";
  text += "farm=" + shellQuote(farm.string()) + "\n";
  if (!job.tasks.empty()) {
    text += "# the frames of each array task\nchunks=(\n";
    for (const auto& chunk : job.tasks) text += "  \"" + frameList(chunk) + "\"\n";
    text += ")\nframes=${chunks[" + scheduler.taskIndexVariable() + "]}\n";
  }
  return text;
}

/// Runs COMMAND for each frame of the task; a failure goes to failed/frame_N.log and fails the
/// task at the end, after the other frames.
std::string perFrameLoop(const std::string& what, const std::string& command) {
  return "mkdir -p \"$farm/failed\"\n"
         "status=0\n"
         "for frame in $frames; do\n"
         "  log=\"$farm/failed/frame_$(printf %06d \"$frame\").log\"\n"
         "  if " + command + " 2>\"$log.tmp\"; then\n"
         "    rm -f \"$log.tmp\" \"$log\"\n"
         "    echo \"frame $frame: " + what + "\"\n"
         "  else\n"
         "    code=$?\n"
         "    echo \"frame $frame: flipscope exited with $code\" >>\"$log.tmp\"\n"
         "    mv -f \"$log.tmp\" \"$log\"\n"
         "    cat \"$log\" >&2\n"
         "    status=1\n"
         "  fi\n"
         "done\n"
         "exit $status\n";
}

FarmJob makeJob(const FarmPlan& plan, const std::string& role, std::vector<std::vector<int>> tasks) {
  const auto farm = farmDirectory(plan.store, plan.kind);
  FarmJob job;
  job.role = role;
  job.tasks = std::move(tasks);
  job.request.name = "flipscope-" + role;
  job.request.script = farm / "scripts" / (role + ".sh");
  job.request.log = farm / "logs" / (role + (job.tasks.empty() ? "_%j.log" : "_%A_%a.log"));
  job.request.tasks = int(job.tasks.size());
  job.request.resources = plan.resources;
  return job;
}

}  // namespace

std::vector<FarmJob> planJobs(const FarmPlan& plan, const std::vector<int>& frames, bool prepare,
                              const Scheduler& scheduler) {
  std::vector<FarmJob> jobs;
  const auto chunks = chunkFrames(frames, plan.chunk);
  const std::string inputs = words(plan.inputs);
  std::string work;  // the role the finalize job waits for
  if (plan.kind == FarmKind::Convert) {
    if (prepare && plan.boundsPass) {
      FarmJob bounds = makeJob(plan, "bounds", chunkFrames(plan.frames, plan.chunk));
      bounds.script = preamble(plan, bounds, scheduler) + "exec \"$flipscope\" farm bounds \"$store\" --task " +
                      scheduler.taskIndexVariable() + " $frames\n";
      jobs.push_back(std::move(bounds));
    }
    if (prepare) {
      FarmJob job = makeJob(plan, "prepare", {});
      // The header as a serial convert chooses it: the domain, and the particle spacing (unless
      // given: --particle-spacing) and the attribute of the first frame that could be read.
      std::string body;
      std::string domain;
      if (plan.boundsPass) {
        body = "reduced=$(\"$flipscope\" farm bounds \"$store\" --reduce) || exit 1\n"
               "domain=${reduced% *}\n"
               "first=${reduced#* }\n";
        domain = " --domain \"$domain\"";
        job.request.afterOk = {"bounds"};
      } else {
        body = "first=" + std::to_string(plan.frames.front()) + "\n";
      }
      body += "exec \"$flipscope\" convert" + inputs + " --frames \"$first\" -o \"$store\" --prepare" + domain +
              words(plan.prepareArgs) + "\n";
      job.script = preamble(plan, job, scheduler) + body;
      jobs.push_back(std::move(job));
    }
    FarmJob convert = makeJob(plan, "convert", chunks);
    if (prepare) convert.request.afterOk = {"prepare"};
    convert.script = preamble(plan, convert, scheduler) +
                     perFrameLoop("converted", "\"$flipscope\" convert" + inputs +
                                                   " --frames \"$frame\" -o \"$store\" --append" +
                                                   words(plan.convertArgs) + " -q");
    jobs.push_back(std::move(convert));
    work = "convert";
  } else {
    FarmJob render = makeJob(plan, "render", chunks);
    render.script = preamble(plan, render, scheduler) +
                    perFrameLoop("rendered", "\"$flipscope\" render \"$store\" --frame \"$frame\" -o " +
                                                 shellQuote(plan.output) + " --camera-file " +
                                                 shellQuote(plan.camera.string()) + words(plan.renderArgs) + " -q");
    jobs.push_back(std::move(render));
    work = "render";
  }
  FarmJob finalize = makeJob(plan, "finalize", {});
  finalize.request.afterAny = {work};
  finalize.script = preamble(plan, finalize, scheduler) + "exec \"$flipscope\" farm finalize \"$store\" --kind " +
                    farmKindName(plan.kind) + "\n";
  jobs.push_back(std::move(finalize));
  return jobs;
}

std::vector<FarmSubmission> submitJobs(std::vector<FarmJob>& jobs, const FarmPlan& plan, Scheduler& scheduler) {
  const auto farm = farmDirectory(plan.store, plan.kind);
  std::filesystem::create_directories(farm / "scripts");
  std::filesystem::create_directories(farm / "logs");
  std::map<std::string, std::string> ids;  // role -> job id
  std::vector<FarmSubmission> submitted;
  for (auto& job : jobs) {
    for (auto* roles : {&job.request.afterOk, &job.request.afterAny})
      for (auto& role : *roles) role = ids.at(role);
    writeTextAtomically(job.request.script, job.script);
    std::filesystem::permissions(job.request.script, std::filesystem::perms::owner_exec,
                                 std::filesystem::perm_options::add);
    try {
      ids[job.role] = scheduler.submit(job.request);
    } catch (const InputError& refused) {
      // Slurm refuses arrays over its MaxArraySize (1001 by default): say how to make fewer tasks.
      const std::string why = refused.what();
      const bool arrayRefused = job.tasks.size() > 1 && why.find("array") != std::string::npos;
      const InputError e(why + (arrayRefused ? " (an array of " + std::to_string(job.tasks.size()) +
                                                   " tasks: a larger --chunk makes fewer)"
                                             : std::string()));
      if (submitted.empty()) throw e;
      std::string before;
      for (const auto& s : submitted) before += " " + s.job;
      throw InputError(std::string(e.what()) + "; the " + scheduler.name() +
                       " jobs submitted before it are queued and should be cancelled:" + before);
    }
    submitted.push_back({job.role, ids[job.role], job.tasks});
    appendSubmissions(farm, {submitted.back()});  // recorded at once: a later failure keeps it
  }
  return submitted;
}

std::string describeJobs(const std::vector<FarmJob>& jobs, const Scheduler& scheduler) {
  std::string text;
  for (const auto& job : jobs) {
    JobRequest request = job.request;
    for (auto* roles : {&request.afterOk, &request.afterAny})
      for (auto& role : *roles) role = "<" + role + " job>";
    std::string command;
    for (const auto& word : scheduler.submitCommand(request)) command += (command.empty() ? "" : " ") + word;
    text += "# " + job.role + ": " + command + "\n";
    text += "# ---- " + request.script.string() + "\n" + job.script + "\n";
  }
  return text;
}

}  // namespace flipscope::farm
