#!/bin/sh
# Builds test_streaming with ThreadSanitizer and runs the Streamer and cache tests under it.
# CI: tests/streaming/run-tsan.sh [build-dir]   (default build-tsan)
set -eu
build=${1:-build-tsan}
cmake -S "$(dirname "$0")/../.." -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DFLIPSCOPE_SANITIZE=thread
ninja -C "$build" -j2 test_streaming
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" ctest --test-dir "$build" --output-on-failure -R 'Streamer|ConvertedBrickCache'
