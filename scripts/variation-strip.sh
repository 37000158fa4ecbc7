#!/bin/bash
# Draws docs/images/variation.png: one task's first frame (render(), 96x96) under 8 seeds (columns)
# for the plain task and its -distracting variant at the Distracting Control Suite's intensities
# (rows: plain, 0.1 easy, 0.2 medium, 0.3 hard), then the plain task with every factor of
# `variation` at 0.3 and procedural floor and sky. Needs a build (build/examples/pixelgym) and
# ffmpeg.
# usage: scripts/variation-strip.sh [TASK-vN] [OUT.png]
set -euo pipefail
task=${1:-CartPoleSwingup-v1}
out=${2:-docs/images/variation.png}
pixelgym=${PIXELGYM:-build/examples/pixelgym}
variant="${task%-v*}-distracting-v${task##*-v}"
cells=$(mktemp -d)
trap 'rm -rf "$cells"' EXIT
size=(--set render_width=96 --set render_height=96)
rows=()
row=0
draw_row() {  # draw_row ID [--set KEY=VALUE ...]
  local id=$1
  shift
  local inputs=()
  for seed in 1 2 3 4 5 6 7 8; do
    "$pixelgym" snapshot "$id" --seed "$seed" "${size[@]}" "$@" --out "$cells/$row-$seed.png" >/dev/null
    inputs+=(-i "$cells/$row-$seed.png")
  done
  ffmpeg -loglevel error -y "${inputs[@]}" -filter_complex hstack=inputs=8 "$cells/row$row.png"
  rows+=(-i "$cells/row$row.png")
  row=$((row + 1))
}
draw_row "$task"
for intensity in 0.1 0.2 0.3; do draw_row "$variant" --set variation=$intensity; done
draw_row "$task" --set variation=0.3 --set sky_texture=noise --set floor_texture=noise
mkdir -p "$(dirname "$out")"
ffmpeg -loglevel error -y "${rows[@]}" -filter_complex vstack=inputs=$row "$out"
echo "wrote $out ($row rows of 8 seeds: $task, $variant at 0.1, 0.2, 0.3, $task at variation=0.3)"
