#include "viewer/CacheConversion.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/Error.h"

extern char** environ;

namespace flipscope::viewer {

std::filesystem::path cacheStorePath(const std::vector<std::string>& inputs, const std::filesystem::path& cacheDir) {
  FLIPSCOPE_CHECK(!inputs.empty(), "no inputs");
  const std::filesystem::path first(inputs.front());
  std::string stem = first.filename().string();
  // Drop compound extensions (.bgeo.sc, .vtk) and the frame pattern with what joins it.
  if (const auto dot = stem.find('.'); dot != std::string::npos && dot > 0) stem = stem.substr(0, dot);
  for (const char* pattern : {"####", "#", "%0", "{}", "$F"})
    if (const auto at = stem.find(pattern); at != std::string::npos) stem = stem.substr(0, at);
  while (!stem.empty() && (stem.back() == '_' || stem.back() == '-' || stem.back() == '.')) stem.pop_back();
  if (stem.empty()) stem = "cache";
  const std::filesystem::path dir = cacheDir.empty() ? first.parent_path() : cacheDir;
  return dir / (stem + ".store");
}

CacheConversion::CacheConversion(const std::filesystem::path& program, const std::vector<std::string>& inputs,
                                 const std::filesystem::path& store, const std::vector<std::string>& extraArgs)
    : mStore(store), mLog(store.parent_path() / (store.filename().string() + ".convert.log")) {
  std::error_code ec;
  if (!store.parent_path().empty()) std::filesystem::create_directories(store.parent_path(), ec);
  if (ec) throw OutputError(store.parent_path(), "cannot create the cache directory: " + ec.message());
  std::vector<std::string> args{program.string(), "convert"};
  args.insert(args.end(), inputs.begin(), inputs.end());
  args.insert(args.end(), {"-o", store.string()});
  args.insert(args.end(), extraArgs.begin(), extraArgs.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, mLog.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const int error = posix_spawn(&mPid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    mPid = -1;
    throw InputError("view: cannot start the conversion (" + program.string() + " convert): " + std::strerror(error));
  }
}

CacheConversion::~CacheConversion() {
  if (mPid <= 0) return;
  if (running()) {
    ::kill(mPid, SIGTERM);
    int status = 0;
    while (::waitpid(mPid, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

bool CacheConversion::running() {
  if (mPid <= 0 || mExitCode >= 0) return false;
  int status = 0;
  const pid_t done = ::waitpid(mPid, &status, WNOHANG);
  if (done == 0) return true;
  if (done == mPid)
    mExitCode = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 1;
  else
    mExitCode = 1;
  return false;
}

std::string CacheConversion::lastLine() const {
  std::ifstream in(mLog, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Progress bars rewrite their line with '\r': the last segment is what a terminal shows.
  std::string last;
  std::string current;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!current.empty()) last = current;
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) last = current;
  return printableText(last);
}

}  // namespace flipscope::viewer
