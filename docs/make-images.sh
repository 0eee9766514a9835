#!/usr/bin/env bash
# Renders every picture of the README into docs/images/ with the commands below (each picture's
# command is also written next to it in the README). Run from the repository root after a
# build: docs/make-images.sh [build/flipscope]
set -euo pipefail
cd "$(dirname "$0")/.."
flipscope=${1:-build/flipscope}
out=docs/images
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

# The bundled Blender Mantaflow FLIP frame (tests/data), converted and rendered with defaults.
vdb=tests/data/mantaflow-dam64/data/fluid_data_0030.vdb
"$flipscope" convert "$vdb" -o "$work/dam" -q
"$flipscope" render "$work/dam" -o "$out/mantaflow-liquid.png" --size 640x360 -q
"$flipscope" render "$work/dam" -o "$out/mantaflow-spheres.png" --size 640x360 --shading spheres -q
"$flipscope" render "$work/dam" -o "$out/mantaflow-unsmoothed.png" --size 640x360 --smoothing none -q

# The same frame with Mantaflow's secondary particles (spray, foam, bubbles): foam as a volume
# (the default), removed, and kept as spheres.
secondary=tests/data/mantaflow-dam64/particles/fluid_particles_0030.vdb
"$flipscope" convert "$vdb" "$secondary" -o "$work/dam-foam" -q
"$flipscope" render "$work/dam-foam" -o "$out/mantaflow-foam-volume.png" --size 640x360 -q
"$flipscope" render "$work/dam-foam" -o "$out/mantaflow-foam-remove.png" --size 640x360 --foam remove -q
"$flipscope" render "$work/dam-foam" -o "$out/mantaflow-foam-keep.png" --size 640x360 --foam keep -q

# The five filters side by side on the same frame and camera.
for filter in rof bilateral curvature-flow narrow-range plane-fit; do
  "$flipscope" render "$work/dam" -o "$out/filter-$filter.png" --size 480x270 --smoothing "$filter" -q
done

# A large synth frame: 20 M particles of waves, sheets and spray.
"$flipscope" synth -o "$work/wave.bin" --particles 20M >/dev/null
"$flipscope" convert "$work/wave.bin" -o "$work/wave" -q
"$flipscope" render "$work/wave" -o "$out/synth20m-liquid.png" --size 640x360 -q
"$flipscope" render "$work/wave" -o "$out/synth20m-unsmoothed.png" --size 640x360 --smoothing none -q
echo "docs/make-images.sh: wrote $(ls "$out" | wc -l) pictures to $out"

# The viewer's window (docs/images/viewer-window.png): `flipscope view` on Mantaflow frame 30 under
# a private Xvfb, captured with xwd and cropped by ImageMagick (Debian: xvfb x11-apps
# imagemagick); skipped when those are missing.
if command -v Xvfb >/dev/null && command -v xwd >/dev/null && command -v convert >/dev/null; then
  "$flipscope" convert "tests/data/mantaflow-dam64/data/fluid_data_0030.vdb" -o "$work/dam30" -q
  Xvfb :87 -screen 0 1600x1000x24 >/dev/null 2>&1 &
  xvfb=$!
  sleep 1
  printf '0 converge\n0.2 drag left 40 10\n0 converge\n3 quit\n' >"$work/events.txt"
  DISPLAY=:87 "$flipscope" view "$work/dam30" --size 900x500 --script "$work/events.txt" -q &
  sleep 4
  DISPLAY=:87 xwd -root -silent >"$work/window.xwd"
  wait $! || true
  kill "$xvfb"
  convert "$work/window.xwd" -crop 900x500+0+0 "$out/viewer-window.png"
fi
