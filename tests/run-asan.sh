#!/bin/sh
# Builds everything with clang, AddressSanitizer and UndefinedBehaviorSanitizer (any report
# aborts the test that caused it) and runs the whole ctest suite under them, GL tests on
# llvmpipe included. The same build holds the libFuzzer targets (FLIPSCOPE_FUZZ), so CI builds
# the sanitized tree once: tests/fuzz/run-fuzz.sh then runs in the same build directory.
# Leaks inside Mesa and the EGL loader, which are not ours, are suppressed (tests/asan.supp);
# the GL tests run without leak checks (below).
# CI: tests/run-asan.sh [build-dir]   (default build-san)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build-san}
# -O1 and line tables only (-g1): reports keep file and line, and the build is much cheaper
# than -O2 -g on CI's two cores.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DFLIPSCOPE_SANITIZE="address;undefined" \
  -DFLIPSCOPE_FUZZ=ON -DFLIPSCOPE_BUILD_TESTS=ON \
  -DFLIPSCOPE_TEST_TIMEOUT=1200 "$@" >/dev/null
ninja -C "$build" -j"${FLIPSCOPE_JOBS:-2}"
export LSAN_OPTIONS="suppressions=$root/tests/asan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The damage sweeps change or cut every 4th byte here (DamageTestSupport.h), not every byte: the
# plain run does every byte, and the fuzzers go further, under these same sanitizers.
export FLIPSCOPE_DAMAGE_STRIDE=4
# Likewise the concurrent converts race once here (ConcurrentConvertTest.cpp), 4 to 6 times there.
export FLIPSCOPE_RACE_ROUNDS=1
# The library tests, leaks included.
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=0" \
  ctest --test-dir "$build" -j2 --output-on-failure -LE "gl|tools"
# The GL tests and the command-line tests (whose renders run on llvmpipe): memory errors abort
# them, but leaks are not checked, since llvmpipe's JIT-compiled code allocates from frames no
# suppression can name.
ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:detect_stack_use_after_return=0" \
  ctest --test-dir "$build" -j2 --output-on-failure -L "gl|tools"
