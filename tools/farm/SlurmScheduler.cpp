// Slurm (https://slurm.schedmd.com): jobs are submitted with `sbatch --parsable`, array tasks
// find their index in SLURM_ARRAY_TASK_ID, dependencies are afterok / afterany with
// --kill-on-invalid-dep (a job whose afterok dependency failed is cancelled, not left pending
// forever). Task states come from squeue (pending and running), then sacct (finished), or
// `scontrol show job` where accounting is disabled (no slurmdbd: sacct refuses).
#include <algorithm>
#include <cstdlib>
#include <map>
#include <sstream>

#include "core/Error.h"
#include "tools/farm/RunProgram.h"
#include "tools/farm/Scheduler.h"

namespace flipscope::farm {
namespace {

std::string joined(const std::vector<std::string>& items, const std::string& separator) {
  std::string text;
  for (const auto& item : items) text += (text.empty() ? "" : separator) + item;
  return text;
}

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

std::vector<std::string> splitFields(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, separator)) fields.push_back(field);
  return fields;
}

/// A task named by Slurm's id of it: "<job>_<index>" for an array task, "<job>" for a job.
TaskState taskWithId(const std::string& id) {
  TaskState s;
  const auto underscore = id.find('_');
  s.job = id.substr(0, underscore);
  s.task = underscore == std::string::npos ? "" : id.substr(underscore + 1);
  return s;
}

/// The first line of a tool's output, for error messages.
std::string firstLine(const std::string& output) {
  const auto lines = splitLines(output);
  return lines.empty() ? std::string("no output") : lines.front();
}

class SlurmScheduler : public Scheduler {
 public:
  std::string name() const override { return "slurm"; }

  std::string directives(const JobRequest& r) const override {
    std::string text = "#SBATCH --job-name=" + shellQuote(r.name) + "\n";
    if (r.tasks > 0) text += "#SBATCH --array=0-" + std::to_string(r.tasks - 1) + "\n";
    text += "#SBATCH --output=" + shellQuote(r.log.string()) + "\n";
    if (!r.resources.partition.empty()) text += "#SBATCH --partition=" + shellQuote(r.resources.partition) + "\n";
    if (!r.resources.time.empty()) text += "#SBATCH --time=" + shellQuote(r.resources.time) + "\n";
    if (r.resources.cpus > 0) text += "#SBATCH --cpus-per-task=" + std::to_string(r.resources.cpus) + "\n";
    if (!r.resources.memory.empty()) text += "#SBATCH --mem=" + shellQuote(r.resources.memory) + "\n";
    return text;
  }

  std::string taskIndexVariable() const override { return "$SLURM_ARRAY_TASK_ID"; }

  std::vector<std::string> submitCommand(const JobRequest& r) const override {
    std::vector<std::string> argv = {"sbatch", "--parsable"};
    std::vector<std::string> dependencies;
    if (!r.afterOk.empty()) dependencies.push_back("afterok:" + joined(r.afterOk, ":"));
    if (!r.afterAny.empty()) dependencies.push_back("afterany:" + joined(r.afterAny, ":"));
    if (!dependencies.empty()) {
      argv.push_back("--dependency=" + joined(dependencies, ","));
      argv.push_back("--kill-on-invalid-dep=yes");
    }
    argv.push_back(r.script.string());
    return argv;
  }

  std::string submit(const JobRequest& r) override {
    const ProgramRun run = runProgram(submitCommand(r));
    if (run.exitCode != 0)
      throw InputError("sbatch " + r.script.string() + " failed (exit " + std::to_string(run.exitCode) +
                       "): " + firstLine(run.output));
    // --parsable: "<id>" or "<id>;<cluster>"
    std::string id = firstLine(run.output);
    id = id.substr(0, id.find(';'));
    if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
      throw InputError("sbatch " + r.script.string() + ": unexpected answer '" + id + "'");
    return id;
  }

  std::vector<TaskState> status(const std::vector<std::string>& jobs) override {
    if (jobs.empty()) return {};
    std::map<std::string, TaskState> tasks;  // by "job_task"
    auto put = [&](TaskState s) { tasks[s.job + "_" + s.task] = std::move(s); };
    // Finished tasks: sacct, or scontrol without accounting.
    const ProgramRun sacct = runProgram({"sacct", "-n", "-P", "-X", "-j", joined(jobs, ","), "-o",
                                         "JobID,JobName,State,ExitCode,Elapsed"});
    if (sacct.exitCode == 0) {
      for (const auto& line : splitLines(sacct.output)) {
        const auto f = splitFields(line, '|');
        if (f.size() < 5) continue;
        TaskState s = taskWithId(f[0]);
        s.name = f[1], s.state = f[2].substr(0, f[2].find(' ')), s.exitCode = f[3], s.elapsed = f[4];
        put(s);
      }
    } else {
      for (const auto& job : jobs) {
        const ProgramRun show = runProgram({"scontrol", "-o", "show", "job", job});
        if (show.exitCode != 0) continue;  // purged: too long ago
        for (const auto& line : splitLines(show.output)) {
          std::map<std::string, std::string> field;
          std::istringstream in(line);
          for (std::string word; in >> word;)
            if (const auto eq = word.find('='); eq != std::string::npos) field[word.substr(0, eq)] = word.substr(eq + 1);
          TaskState s;
          s.job = field.count("ArrayJobId") ? field["ArrayJobId"] : field["JobId"];
          s.task = field.count("ArrayTaskId") ? field["ArrayTaskId"] : "";
          s.name = field["JobName"], s.state = field["JobState"], s.elapsed = field["RunTime"];
          s.exitCode = field["ExitCode"];
          if (field["Reason"] != "None") s.reason = field["Reason"];
          put(s);
        }
      }
    }
    // Live tasks: squeue has the latest word on pending and running ones.
    const ProgramRun squeue = runProgram({"squeue", "-h", "-r", "-j", joined(jobs, ","), "-o", "%i|%j|%T|%M|%r"});
    if (squeue.exitCode == 0) {
      for (const auto& line : splitLines(squeue.output)) {
        const auto f = splitFields(line, '|');
        if (f.size() < 5) continue;
        TaskState s = taskWithId(f[0]);
        s.name = f[1], s.state = f[2], s.elapsed = f[3], s.reason = f[4] == "None" ? "" : f[4];
        put(s);
      }
    } else if (sacct.exitCode != 0 && tasks.empty()) {
      throw InputError("cannot ask Slurm about job " + joined(jobs, ",") + ": squeue: " + firstLine(squeue.output));
    }
    std::vector<TaskState> list;
    for (auto& [key, s] : tasks) list.push_back(std::move(s));
    const auto number = [](const std::string& text) { return std::atol(text.c_str()); };
    std::stable_sort(list.begin(), list.end(), [&](const TaskState& a, const TaskState& b) {
      return number(a.job) != number(b.job) ? number(a.job) < number(b.job) : number(a.task) < number(b.task);
    });
    return list;
  }

  bool ended(const std::string& job) override {
    const ProgramRun run = runProgram({"squeue", "-h", "-j", job, "-o", "%T"});
    if (run.exitCode == 0) return splitLines(run.output).empty();
    // "Invalid job id specified": purged long ago. Any other error (a controller that does not
    // answer for a moment) says nothing: not ended.
    return run.output.find("Invalid job id") != std::string::npos;
  }
};

}  // namespace

std::unique_ptr<Scheduler> makeSlurmScheduler() { return std::make_unique<SlurmScheduler>(); }

}  // namespace flipscope::farm
