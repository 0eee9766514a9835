#!/bin/sh
# Builds the libFuzzer targets (clang, ASan + UBSan, FLIPSCOPE_FUZZ=ON) into BUILD_DIR and runs
# each for SECONDS (with RUNS: for that many inputs from the fixed seed 1, so a run is the same on
# every machine, stopping at SECONDS if it is slower: what CI does), FLIPSCOPE_JOBS (2) at a
# time, from its seed corpus (tests/fuzz/corpus/<target>; new inputs go to
# BUILD_DIR/fuzz-run, not into the repository). Fails on any crash, leak, timeout (10 s an
# input) or memory beyond 2 GiB; the input that did it is left in BUILD_DIR/fuzz-run/.
# CI: tests/fuzz/run-fuzz.sh [build-dir] [seconds] [runs]   (defaults build-fuzz, 30, unlimited)
# A crasher, once fixed, goes into tests/fuzz/regressions/<target>/ (see FuzzRegressionTest.cpp).
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build-fuzz}
seconds=${2:-30}
runs_limit=${3:-}
limit="-max_total_time=$seconds"
[ -n "$runs_limit" ] && limit="-runs=$runs_limit -seed=1 -max_total_time=$seconds"
jobs=${FLIPSCOPE_JOBS:-2}
# A build directory that tests/run-asan.sh configured (the same clang, sanitizers and fuzz
# targets, with the tests) is used as it is.
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DFLIPSCOPE_FUZZ=ON -DFLIPSCOPE_BUILD_TESTS=OFF -DFLIPSCOPE_SANITIZE="address;undefined" >/dev/null
fi
ninja -C "$build" -j"$jobs" flipscope_fuzzers
work="$build/fuzz-run"
rm -rf "$work"
mkdir -p "$work"
# fuzz_one NAME BINARY: one target from its seeds; a failure leaves NAME.failed beside its log.
fuzz_one() {
  mkdir -p "$work/$1"
  if ! ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$2" $limit -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$work/$1-" "$work/$1" "$root/tests/fuzz/corpus/$1" >"$work/$1.log" 2>&1; then
    touch "$work/$1.failed"
  fi
}
# $jobs targets at a time (each is one process on one core).
names=""
running=0
for pair in vdb_points:VdbPoints ply:Ply raw:Raw vtk:Vtk vtu:Vtu bgeo:Bgeo bgeo_sc:BgeoSc classic_bgeo:ClassicBgeo \
  prt:Prt realflow_bin:RealFlow pdb:Pdb gzip:Gzip store_header:StoreHeader frame_index:FrameIndex brick_payload:BrickPayload \
  camera:Camera; do
  name=${pair%%:*}
  names="$names $name"
  echo "fuzz: $name"
  fuzz_one "$name" "$build/tests/fuzz/${pair#*:}Fuzz" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait
    running=0
  fi
done
wait
summary=""
failed=""
for name in $names; do
  log="$work/$name.log"
  if [ -f "$work/$name.failed" ]; then
    failed="$failed $name"
    tail -n 60 "$log"
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  summary="$summary$(printf '%-14s %10s runs %8s/s' "$name" "${runs:-?}" "${rate:-?}")
"
done
printf 'fuzz summary (%s s each):\n%s' "$seconds" "$summary"
if [ -n "$failed" ]; then
  echo "fuzz: FAILED:$failed (inputs and logs in $work)"
  exit 1
fi
echo "fuzz: no crash, leak or timeout"
