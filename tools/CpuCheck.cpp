// CpuCheck: a binary built for x86-64-v2 (FLIPSCOPE_X86_64_LEVEL, CMakeLists.txt) says so and
// exits on a CPU without POPCNT or SSE4.2, instead of dying of an illegal instruction somewhere
// later. This file alone is compiled for the baseline (tools/CMakeLists.txt), and the check runs
// as a constructor of the highest priority: before main and before the other constructors.
#if defined(FLIPSCOPE_CHECK_X86_64_V2)
#include <unistd.h>

#include "core/Error.h"

namespace {

__attribute__((constructor(101))) void requireX86_64Level() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("popcnt") && __builtin_cpu_supports("ssse3") && __builtin_cpu_supports("sse4.1") &&
      __builtin_cpu_supports("sse4.2"))
    return;
  static const char kMessage[] =
      "flipscope: error: this CPU lacks POPCNT or SSE4.2 (x86-64-v2), which this build of flipscope needs; "
      "build it with cmake -DFLIPSCOPE_X86_64_LEVEL=x86-64\n";
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  ::_exit(flipscope::kExitFailure);
}

}  // namespace
#endif
