// The farm's scheduler, behind one small interface: Slurm today (SlurmScheduler.cpp). A job
// is a bash script (FarmScripts.h) that the scheduler runs once, or as an array of tasks that
// each find their index in taskIndexVariable(). Another scheduler (Deadline, Tractor, OpenCue)
// plugs in by implementing these five members: the script directives, the index variable,
// submitting with dependencies, the state of a job's tasks, and whether a job has ended.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace flipscope::farm {

/// What every task of a job asks the scheduler for; empty / 0: the scheduler's default.
struct FarmResources {
  std::string partition;  ///< queue, pool or partition
  std::string time;       ///< wall-time limit, e.g. "2:00:00"
  int cpus = 0;           ///< per task
  std::string memory;     ///< per task, e.g. "16G"
};

struct JobRequest {
  std::string name;                ///< e.g. "flipscope-convert"
  std::filesystem::path script;    ///< the bash script to run
  std::filesystem::path log;       ///< stdout and stderr of each task (the scheduler's %-codes)
  int tasks = 0;                   ///< array tasks 0..tasks-1; 0: a single task
  std::vector<std::string> afterOk;   ///< starts once these jobs all succeeded (else never)
  std::vector<std::string> afterAny;  ///< starts once these jobs all ended, however
  FarmResources resources;
};

/// One task of a submitted job, as the scheduler reports it.
struct TaskState {
  std::string job;       ///< job id
  std::string task;      ///< array index ("" for a single task; "2-5" for pending ones)
  std::string name;
  std::string state;     ///< the scheduler's word: PENDING, RUNNING, COMPLETED, FAILED, ...
  std::string exitCode;  ///< "0:0" (code:signal) once ended, else ""
  std::string elapsed;
  std::string reason;    ///< why it waits, when it does
};

class Scheduler {
 public:
  virtual ~Scheduler() = default;
  virtual std::string name() const = 0;
  /// The lines at the top of a job script that ask for `request` (for Slurm, #SBATCH lines).
  virtual std::string directives(const JobRequest& request) const = 0;
  /// The shell expression of a task's array index, e.g. "$SLURM_ARRAY_TASK_ID".
  virtual std::string taskIndexVariable() const = 0;
  /// The command line that submits `request` (what --dry-run prints); job ids of dependencies
  /// that are not submitted yet are written as <role>.
  virtual std::vector<std::string> submitCommand(const JobRequest& request) const = 0;
  /// Submits; returns the job id. Throws InputError with the scheduler's message.
  virtual std::string submit(const JobRequest& request) = 0;
  /// Every task of these jobs the scheduler still knows. Throws InputError when it cannot ask.
  virtual std::vector<TaskState> status(const std::vector<std::string>& jobs) = 0;
  /// The job has ended (all its tasks), or the scheduler no longer knows it.
  virtual bool ended(const std::string& job) = 0;
};

/// Slurm through sbatch, squeue, sacct and scontrol (on PATH; SLURM_CONF as the user set it).
std::unique_ptr<Scheduler> makeSlurmScheduler();

}  // namespace flipscope::farm
