#!/bin/sh
# Builds test_streaming and test_preprocess with ThreadSanitizer and runs the threaded parts
# under it: the Streamer and its cache, and convert's read-ahead (PrefetchingSource), scattered
# reads (InputFile), reads around the page cache (DirectReadAhead), spill writer
# (BackgroundAppender) and the spill buckets' read-ahead beside their removal (SpillBucketsThreads). (Not the TBB loops: Debian's oneTBB library is not instrumented,
# and TSan reports its partitioner.)
# CI: tests/streaming/run-tsan.sh [build-dir]   (default build-tsan)
set -eu
build=${1:-build-tsan}
cmake -S "$(dirname "$0")/../.." -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DFLIPSCOPE_SANITIZE=thread
ninja -C "$build" -j2 test_streaming test_preprocess
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" ctest --test-dir "$build" --output-on-failure \
  -R 'Streamer|ConvertedBrickCache|PrefetchingSource|InputFile|DirectReadAhead|BackgroundAppender|SpillBucketsThreads'
