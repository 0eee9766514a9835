#!/usr/bin/env bash
# GPU checks and benchmarks, for a machine with a hardware GPU (README "On a GPU"): which EGL
# device flipscope finds, the GL tests against the CPU reference, and the GPU benches.
# Usage: tools/gpu-check.sh [OUT_DIR]   (default gpu-check/). Runs build/flipscope and the
# build's test_*_gl; each step has a time limit, and a failed step does not stop the rest.
set -uo pipefail
cd "$(dirname "$0")/.."
out=${1:-gpu-check}
mkdir -p "$out"
fs=build/flipscope
log=$out/log.txt
step() { echo "== $* ($(date +%T))" | tee -a "$log"; }
step machine
{ nvidia-smi -L; nproc; free -g | head -2; } 2>&1 | tee -a "$log"
step devices
$fs devices 2>&1 | tee -a "$log"
grep -q "auto: OpenGL" "$log" || { step "no hardware OpenGL: --device auto would use the CPU; stopping"; exit 1; }
# The GPU's clocks and power through the rest (a warm frame's time depends on them).
nvidia-smi dmon -s pc -o T >"$out/dmon.txt" 2>&1 &
dmon=$!
trap 'kill $dmon 2>/dev/null' EXIT
for t in $(find build/tests -name 'test_*_gl' -type f | sort); do
  step "$t"
  timeout 300 "$t" --gtest_brief=1 2>&1 | tail -30 | tee -a "$log"
done
step bench render
timeout 600 $fs bench render --particles 100M --sizes 1280x720,1920x1080 --device gpu --no-vdb-tool \
  --work-dir /tmp/flipscope-gpu-render 2>&1 | tee "$out/bench_render.txt"
rm -rf /tmp/flipscope-gpu-render
step bench surface
timeout 300 $fs bench surface --device gpu 2>&1 | tee "$out/bench_surface.txt"
step bench view
timeout 300 $fs bench view --devices gpu 2>&1 | tee "$out/bench_view.txt"
step bench scale
timeout 900 $fs bench scale --particles 500M --device gpu --work-dir /tmp/flipscope-gpu-scale 2>&1 |
  tee "$out/bench_scale.txt"
rm -rf /tmp/flipscope-gpu-scale
step end
